//! The `shading` target: one mesh (a real piece with normals and texture
//! coordinates from the blob, or a small arbitrary one), a texture, lights
//! and a material from arbitrary bytes, rendered through every shading.
//!
//! Input layout (little-endian): `u32 n`, an `n`-byte mesh blob (below;
//! `n = 0`: none, the small mesh of [`ShadeIn`] is used), then the rest
//! through `arbitrary` ([`ShadeIn`]). Blob (every field optional):
//!
//! ```text
//! u16 width, u16 height  frame size override (0: keep ShadeIn's)
//! u8 flags               bit 0-1 backend (0 default, 1 micromath, 2 libm),
//!                        bit 2 bounding sphere, bit 3-4 colour mode,
//!                        bit 5 lists not cut (ignore `ShadeIn::cut`),
//!                        bit 6 rows from 0 (as many as the budget
//!                        allows), bit 7 a stock texture and stock lights
//!                        where the input's are refused (after checking
//!                        the refusal)
//! f32 x 10               eye xyz, target xyz, fov, near, far, angle_y
//! u16 vertices           then per vertex 8 i16: position (/ 8192),
//!                        normal (/ 8192), uv (/ 4096)
//! u16 triples            the triangles, to the end (at most 3000)
//! ```
//!
//! Checks (the core's promises, `src/shade.rs`, `src/pipeline.rs`):
//!
//! - `Texture::new` is `Err(TextureSize { width, height, texels })`
//!   exactly when a side is 0 or above `MAX_TEXTURE_SIDE` or the texel
//!   count is not `width * height`; `Lighting::new` is
//!   `Err(InvalidLighting)` exactly when its documented conditions hold
//!   (more than `MAX_LIGHTS` lights, a zero or non-finite direction or
//!   view, a non-finite colour or ambient);
//! - every shading (`N = 3` `MeshColors` and `LitColors` with
//!   `VertexColor`, `N = 5` `ColorUv` + `Textured`, `N = 6` `ColorNormal` +
//!   `Phong`, `N = 8` `ColorUvNormal` + textured `Phong`), through
//!   `submit_mesh` and `submit_mesh_cached`, gives the id and depth
//!   buffers and the `Stats` of the colour frame on the same mesh whose
//!   triangles missing an attribute of that shading were given an
//!   out-of-range index (`rejected_index`) and whose vertices with a
//!   non-finite varying of that shading (a uv) a NaN colour
//!   (`rejected_nonfinite`, after the frustum and strip tests): see
//!   [`oracle`] (with complete, finite lists: the colour frame itself);
//! - `submit_mesh` and `submit_mesh_cached` agree (stats, ids, depth,
//!   colour), the counters add up, depth does not depend on the pixel
//!   type;
//! - `StripRenderer::with_shader`, strip by strip over the row window,
//!   gives the frame's rows (colour and depth) and counts what the frame
//!   counts; nothing is written outside the rows asked for (guards).

use crate::{camera, check_accounting, debug, Backend, FrameParams, Guarded, MatIn, F};
use libfuzzer_sys::arbitrary::{self, Arbitrary, Unstructured};
use microraster::pixelcolor::{Rgb565, Rgb888};
use microraster::prelude::{DepthWord, Submit};
use microraster::shade::{
    ColorNormal, ColorUv, ColorUvNormal, DirectionalLight, Filter, Lighting, LitColors, Material,
    NoTexture, PerVertex, Phong, Texel, Texture, Textured, Wrap, MAX_LIGHTS, MAX_TEXTURE_SIDE,
};
use microraster::{
    Attributes, BoundingSphere, Config, Error, FragmentShader, Frame, Mesh, MeshColors,
    ProcessedVertex, SetupTriangle, Stats, StripRenderer, TriangleId, Vec3, VertexColor,
};

/// At most this many pixels per rendered window.
const BUDGET: usize = 1 << 14;
/// Largest number of triangles taken from a blob.
const MAX_BLOB_TRIANGLES: usize = 3000;
/// At most this many strips per strip-renderer pass.
const MAX_STRIPS: u32 = 4;

/// A texture side, often an edge case.
#[derive(Clone, Copy, Debug)]
pub struct Side(pub u32);

impl<'a> Arbitrary<'a> for Side {
    fn arbitrary(u: &mut Unstructured<'a>) -> arbitrary::Result<Self> {
        const S: [u32; 16] = [0, 1, 2, 3, 4, 5, 7, 8, 15, 16, 17, 31, 32, 33, 63, 64];
        let t: u8 = u.arbitrary()?;
        Ok(Side(match t % 4 {
            0 | 1 => S[(t as usize >> 2) % S.len()],
            2 => 1 + (t as u32 >> 2) % 64,
            _ => [MAX_TEXTURE_SIDE, MAX_TEXTURE_SIDE + 1, u32::MAX, 6][(t as usize >> 2) % 4],
        }))
    }
}

/// A texture.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub struct TexIn {
    /// Width.
    pub width: Side,
    /// Height.
    pub height: Side,
    /// Texel count change against `width * height` (`% 4 == 0`: by
    /// `delta.1`, else none).
    pub delta: (u8, i8),
    /// Rgb565 texels (else Rgb888).
    pub rgb565: bool,
    /// Texel pattern seed.
    pub seed: u32,
    /// Bilinear (else nearest).
    pub bilinear: bool,
    /// Clamp (else repeat).
    pub clamp: bool,
}

/// A directional light.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub struct LightIn {
    /// Direction towards the light.
    pub direction: [F; 3],
    /// Intensity.
    pub color: [F; 3],
}

/// The structured part of a `shading` input.
#[derive(Arbitrary, Clone, Debug)]
pub struct ShadeIn {
    /// Frame settings.
    pub params: FrameParams,
    /// The small mesh's matrix.
    pub mvp: MatIn,
    /// Small mesh: positions (at most 40).
    pub positions: Vec<[F; 3]>,
    /// Small mesh: triangles (at most 80; indices `% (len + 2)`).
    pub indices: Vec<[u8; 3]>,
    /// Small mesh: normals (at most 40, may be shorter).
    pub normals: Vec<[F; 3]>,
    /// Small mesh: texture coordinates (at most 40, may be shorter).
    pub uvs: Vec<[F; 2]>,
    /// Colours (small mesh; for the blob's, a non-empty list replaces
    /// the colours made from the positions).
    pub colors: Vec<[u8; 3]>,
    /// 0: uniform, 1: per triangle, 2: per vertex.
    pub color_mode: u8,
    /// Blob lists cut short by this many (normals, uvs, colours; 0: not).
    pub cut: [u8; 3],
    /// Bounding sphere (small mesh).
    pub bounds: bool,
    /// First triangle id.
    pub first_id: u32,
    /// Extra vertex-cache entries.
    pub extra_cache: u8,
    /// The texture.
    pub tex: TexIn,
    /// Lights (at most 6 are used).
    pub lights: Vec<LightIn>,
    /// Ambient.
    pub ambient: [F; 3],
    /// Towards the viewer.
    pub view: [F; 3],
    /// Specular colour.
    pub specular: [F; 3],
    /// Shininess (clamped to 1024 by `shade`).
    pub shininess: u16,
    /// `ColorUv` over `LitColors` (else `MeshColors`).
    pub lit_uv: bool,
    /// Rows to render: first row and row count.
    pub window: (u16, u16),
    /// Strip height for the strip renderers (0 stands for 1).
    pub strip: u8,
}

/// A whole `shading` input.
#[derive(Clone, Debug)]
pub struct ShadeInput {
    /// The blob, if any.
    pub blob: Option<Blob>,
    /// The rest.
    pub rest: ShadeIn,
}

impl<'a> Arbitrary<'a> for ShadeInput {
    fn arbitrary(u: &mut Unstructured<'a>) -> arbitrary::Result<Self> {
        let n = u.len().min(u.arbitrary::<u32>()? as usize);
        let b = u.bytes(n)?;
        Ok(ShadeInput {
            blob: (!b.is_empty()).then(|| Blob::parse(b)),
            rest: ShadeIn::arbitrary(u)?,
        })
    }
    fn arbitrary_take_rest(u: Unstructured<'a>) -> arbitrary::Result<Self> {
        let data = u.take_rest();
        let (b, rest) = crate::big::split_input(data);
        Ok(ShadeInput {
            blob: (!b.is_empty()).then(|| Blob::parse(b)),
            rest: ShadeIn::arbitrary_take_rest(Unstructured::new(rest))?,
        })
    }
}

/// A mesh with normals and texture coordinates read from the blob.
#[derive(Clone, Debug, Default)]
pub struct Blob {
    /// Frame size override.
    pub size: Option<(u32, u32)>,
    /// Flags.
    pub flags: u8,
    /// Camera numbers.
    pub camera: [f32; 10],
    /// Positions.
    pub positions: Vec<Vec3>,
    /// Normals.
    pub normals: Vec<Vec3>,
    /// Texture coordinates.
    pub uvs: Vec<[f32; 2]>,
    /// Triangles.
    pub indices: Vec<[u32; 3]>,
}

impl Blob {
    /// Parses a blob (never fails).
    pub fn parse(mut b: &[u8]) -> Blob {
        fn take<const K: usize>(b: &mut &[u8]) -> Option<[u8; K]> {
            let (a, r) = b.split_first_chunk::<K>()?;
            *b = r;
            Some(*a)
        }
        let mut m = Blob::default();
        let w = take::<2>(&mut b).map_or(0, u16::from_le_bytes) as u32;
        let h = take::<2>(&mut b).map_or(0, u16::from_le_bytes) as u32;
        if w != 0 && h != 0 {
            m.size = Some((w, h));
        }
        m.flags = take::<1>(&mut b).map_or(0, |x| x[0]);
        for c in m.camera.iter_mut() {
            *c = take::<4>(&mut b).map_or(0.0, f32::from_le_bytes);
        }
        let nv = take::<2>(&mut b).map_or(0, u16::from_le_bytes) as usize;
        for _ in 0..nv {
            let Some(v) = take::<16>(&mut b) else { break };
            let c = |k: usize| i16::from_le_bytes([v[2 * k], v[2 * k + 1]]) as f32;
            m.positions
                .push(Vec3::new(c(0) / 8192.0, c(1) / 8192.0, c(2) / 8192.0));
            m.normals
                .push(Vec3::new(c(3) / 8192.0, c(4) / 8192.0, c(5) / 8192.0));
            m.uvs.push([c(6) / 4096.0, c(7) / 4096.0]);
        }
        while m.indices.len() < MAX_BLOB_TRIANGLES {
            let Some(t) = take::<6>(&mut b) else { break };
            let c = |k: usize| u16::from_le_bytes([t[2 * k], t[2 * k + 1]]) as u32;
            m.indices.push([c(0), c(1), c(2)]);
        }
        m
    }
}

/// The mesh in the core's types.
#[derive(Clone, Debug)]
struct Owned {
    positions: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    normals: Vec<Vec3>,
    uvs: Vec<[f32; 2]>,
    colors: Vec<Rgb888>,
    mode: u8,
    bounds: Option<BoundingSphere>,
    mvp: microraster::Mat4,
    first_id: u32,
}

fn v3(a: [F; 3]) -> Vec3 {
    Vec3::new(a[0].0, a[1].0, a[2].0)
}

fn cut<T>(v: &mut Vec<T>, by: u8) {
    let n = v.len().saturating_sub(by as usize);
    v.truncate(n);
}

impl Owned {
    fn new(input: &ShadeInput, aspect: f32) -> Owned {
        let r = &input.rest;
        let mode = r.color_mode % 3;
        let colors_from = |n: usize| -> Vec<Rgb888> {
            (0..n)
                .map(|i| {
                    let c = r.colors[i % r.colors.len()];
                    Rgb888::new(c[0], c[1], c[2])
                })
                .collect()
        };
        if let Some(b) = &input.blob {
            let backend = match b.flags & 3 {
                0 => Backend::Default,
                1 => Backend::Micromath,
                _ => Backend::Libm,
            };
            let n = if (b.flags >> 3) & 3 == 1 {
                b.indices.len()
            } else {
                b.positions.len()
            };
            let colors = if r.colors.is_empty() {
                (0..n)
                    .map(|i| {
                        let p = b.positions.get(i % b.positions.len().max(1)).copied();
                        let p = p.unwrap_or(Vec3::new(0.0, 0.0, 0.0));
                        let c = |v: f32| ((v * 0.5 + 0.5).clamp(0.0, 1.0) * 255.0) as u8;
                        Rgb888::new(c(p.x), c(p.y), c(p.z))
                    })
                    .collect()
            } else {
                colors_from(n)
            };
            let mut o = Owned {
                positions: b.positions.clone(),
                indices: b.indices.clone(),
                normals: b.normals.clone(),
                uvs: b.uvs.clone(),
                colors,
                mode: ((b.flags >> 3) & 3) % 3,
                bounds: None,
                mvp: camera(b.camera, aspect, 0.0, backend),
                first_id: r.first_id,
            };
            if b.flags & 32 == 0 {
                cut(&mut o.normals, r.cut[0]);
                cut(&mut o.uvs, r.cut[1]);
                cut(&mut o.colors, r.cut[2]);
            }
            if b.flags & 4 != 0 {
                o.bounds = BoundingSphere::from_points(&o.positions);
            }
            o
        } else {
            let positions: Vec<Vec3> = r.positions.iter().take(40).map(|p| v3(*p)).collect();
            let np = positions.len() as u32 + 2;
            let indices = r
                .indices
                .iter()
                .take(80)
                .map(|t| t.map(|i| i as u32 % np))
                .collect::<Vec<_>>();
            let n = if mode == 1 {
                indices.len()
            } else {
                positions.len()
            };
            let colors = if r.colors.is_empty() {
                vec![Rgb888::new(255, 255, 255); n]
            } else {
                // A few short of the mesh now and then.
                let mut c = colors_from(n);
                cut(&mut c, r.cut[2] % 4);
                c
            };
            Owned {
                bounds: if r.bounds {
                    BoundingSphere::from_points(&positions)
                } else {
                    None
                },
                positions,
                indices,
                normals: r.normals.iter().take(40).map(|p| v3(*p)).collect(),
                uvs: r.uvs.iter().take(40).map(|p| [p[0].0, p[1].0]).collect(),
                colors,
                mode,
                mvp: r.mvp.matrix(),
                first_id: r.first_id,
            }
        }
    }

    fn colors(&self) -> MeshColors<'_> {
        match self.mode {
            0 => MeshColors::Uniform(
                self.colors
                    .first()
                    .copied()
                    .unwrap_or(Rgb888::new(9, 99, 199)),
            ),
            1 => MeshColors::PerTriangle(&self.colors),
            _ => MeshColors::PerVertex(&self.colors),
        }
    }

    fn mesh<A>(&self, attributes: A) -> Mesh<'_, A> {
        Mesh {
            positions: &self.positions,
            indices: &self.indices,
            attributes,
            bounds: self.bounds,
        }
    }

    /// The harness's own view of whether triangle `i` has a colour.
    fn has_color(&self, i: usize, idx: [u32; 3]) -> bool {
        match self.mode {
            0 => true,
            1 => i < self.colors.len(),
            _ => idx.iter().all(|&k| (k as usize) < self.colors.len()),
        }
    }
}

fn all_in(len: usize, idx: [u32; 3]) -> bool {
    idx.iter().all(|&k| (k as usize) < len)
}

/// Which lists a shading needs.
#[derive(Clone, Copy, Debug)]
struct Needs {
    /// Normals (sanitised: a non-finite one is lit by ambient only).
    normals: bool,
    /// Texture coordinates (varyings as they are: a non-finite one
    /// rejects the triangle).
    uvs: bool,
}

/// What one frame pass produced.
#[derive(Debug)]
struct Pass {
    stats: Stats,
    ids: Vec<TriangleId>,
    depth: Vec<u32>,
    rgb: Vec<Rgb888>,
}

/// The rendering context.
struct Ctx {
    config: Config,
    y0: u32,
    y1: u32,
    strip: u32,
    extra_cache: usize,
}

/// One frame of `N` varyings: the mesh through `submit_mesh` (`cached`
/// false) or `submit_mesh_cached`, rendered into ids + depth and colour +
/// depth.
fn frame_pass<const S: u32, const N: usize, A: Attributes<N> + Copy, Fr: FragmentShader<N>>(
    ctx: &Ctx,
    o: &Owned,
    mesh: &Mesh<'_, A>,
    frag: &Fr,
    cached: bool,
) -> Pass {
    let n = mesh.indices.len();
    let mut storage = vec![SetupTriangle::<N>::EMPTY; 7 * n];
    let mut frame = Frame::<S, N>::with_subpixel_bits(ctx.config, &mut storage).expect("valid");
    let r = if cached {
        let mut cache = vec![ProcessedVertex::EMPTY; mesh.positions.len() + ctx.extra_cache];
        frame.submit_mesh_cached(mesh, &o.mvp, o.first_id, &mut cache)
    } else {
        frame.submit_mesh(mesh, &o.mvp, o.first_id)
    };
    assert_eq!(r, Ok(()), "a frame with room for everything refused a mesh");
    let stats = frame.stats();
    check_accounting(&Stats::default(), &stats, n as u64);
    assert_eq!(stats.outside_strip, 0);
    assert_eq!(frame.triangles().len() as u64, stats.stored);
    let h = ctx.config.height;
    for t in frame.triangles() {
        let (a, b) = t.rows();
        assert!(a <= b && (b as u32) < h, "rows {a}..={b} of {h}");
    }
    let len = ctx.config.width as usize * (ctx.y1 - ctx.y0) as usize;
    let mut ids = Guarded::new(len, TriangleId(0), TriangleId(0xdead_beef));
    let mut d1 = Guarded::new(len, u32::FAR, 0x5a5a_5a5a);
    frame
        .render_rows_shaded(ctx.y0, ctx.y1, ids.inner(), d1.inner(), frag)
        .expect("render_rows_shaded");
    ids.check_guards();
    d1.check_guards();
    let mut rgb = Guarded::new(len, Rgb888::new(1, 2, 3), Rgb888::new(0xde, 0xad, 0xbe));
    let mut d2 = Guarded::new(len, u32::FAR, 0x5a5a_5a5a);
    frame
        .render_rows_shaded(ctx.y0, ctx.y1, rgb.inner(), d2.inner(), frag)
        .expect("render_rows_shaded");
    rgb.check_guards();
    d2.check_guards();
    assert!(
        d1.get() == d2.get(),
        "depth depends on the pixel type (N = {N})"
    );
    Pass {
        stats,
        ids: ids.get().to_vec(),
        depth: d1.get().to_vec(),
        rgb: rgb.get().to_vec(),
    }
}

/// Strip renderers of `N` varyings over the window, strip by strip, each
/// into a guarded buffer; checked against the frame's rows `want`.
fn strip_pass<
    const S: u32,
    const N: usize,
    A: Attributes<N> + Copy,
    Fr: FragmentShader<N> + Copy,
>(
    ctx: &Ctx,
    o: &Owned,
    mesh: &Mesh<'_, A>,
    frag: Fr,
    passes: [&Pass; 2],
    name: &str,
) {
    let w = ctx.config.width as usize;
    let rows = ctx.y1 - ctx.y0;
    let sh = ctx.strip.max(rows.div_ceil(MAX_STRIPS)).max(1);
    let mut y = ctx.y0;
    let mut k = 0;
    while y < ctx.y1 {
        let e = (y + sh).min(ctx.y1);
        let len = w * (e - y) as usize;
        let off = (y - ctx.y0) as usize * w;
        // Odd strips take submit_mesh_cached, checked against the frame
        // that did.
        let want = passes[k % 2];
        let mut c = Guarded::new(len, Rgb888::new(1, 2, 3), Rgb888::new(0xde, 0xad, 0xbe));
        let mut d = Guarded::new(len, u32::FAR, 0x5a5a_5a5a);
        let (st, _) = {
            let (cs, ds) = (c.inner(), d.inner());
            let mut sr = StripRenderer::<Rgb888, [u32], S, N, Fr>::with_shader(
                ctx.config, y, e, cs, ds, frag,
            )
            .expect("strip renderer");
            let r = if k % 2 == 1 {
                let mut cache = vec![ProcessedVertex::EMPTY; mesh.positions.len()];
                sr.submit_mesh_cached(mesh, &o.mvp, o.first_id, &mut cache)
            } else {
                sr.submit_mesh(mesh, &o.mvp, o.first_id)
            };
            assert_eq!(r, Ok(()), "a strip renderer refused a mesh");
            (sr.stats(), sr.render_stats())
        };
        c.check_guards();
        d.check_guards();
        check_accounting(&Stats::default(), &st, mesh.indices.len() as u64);
        assert_eq!(st.submitted, want.stats.submitted);
        assert!(
            st.stored <= want.stats.stored,
            "{name}: {st:?} vs {:?}",
            want.stats
        );
        if y == 0 && e == ctx.config.height {
            assert_eq!(
                st, want.stats,
                "{name}: a whole-frame strip renderer counts differently"
            );
        }
        assert!(
            c.get() == &want.rgb[off..off + len],
            "{name}: StripRenderer {y}..{e} colour differs from the frame"
        );
        assert!(
            d.get() == &want.depth[off..off + len],
            "{name}: StripRenderer {y}..{e} depth differs from the frame"
        );
        y = e;
        k += 1;
    }
}

/// The colour frame on `o` as the shading with `needs` must count, store
/// and draw it (only `Stats`, ids and depth are compared), in the
/// documented order of the checks:
///
/// - a triangle lacking an attribute the shading reads is given an
///   out-of-range index: `rejected_index`, before any position test, as a
///   missing attribute is;
/// - a vertex where the shading's varyings are not finite (its uv, with
///   `needs.uvs`: colours and lit colours are always finite, non-finite
///   normals are lit by ambient only) gets a NaN colour, through
///   `PerVertex` raw varyings (`FINITE = false`), so a triangle using it is
///   `rejected_nonfinite` after the position, frustum and strip tests and
///   before setup (outside the frustum it stays `culled_frustum`).
///
/// Other vertices keep their colour (per-triangle colours, which
/// `PerVertex` cannot give, are triangle 0's: colour is not compared).
/// `None` where nothing is masked or poisoned (the colour frame itself is
/// the oracle).
fn oracle<const S: u32>(ctx: &Ctx, o: &Owned, needs: Needs, cached: bool) -> Option<Pass> {
    let mut m = o.clone();
    let mut masked = 0;
    for (i, t) in m.indices.iter_mut().enumerate() {
        let ok = o.has_color(i, *t)
            && (!needs.normals || all_in(o.normals.len(), *t))
            && (!needs.uvs || all_in(o.uvs.len(), *t));
        if !ok {
            *t = [u32::MAX; 3];
            masked += 1;
        }
    }
    let colors = o.colors();
    let mut poisoned = 0;
    let varyings: Vec<[f32; 3]> = (0..o.positions.len() as u32)
        .map(|k| {
            let uv_bad = o
                .uvs
                .get(k as usize)
                .is_some_and(|uv| !uv.iter().all(|c| c.is_finite()));
            if needs.uvs && uv_bad {
                poisoned += 1;
                [f32::NAN; 3]
            } else {
                colors.get(0, k)
            }
        })
        .collect();
    debug(|| format!("oracle {needs:?}: {masked} masked, {poisoned} vertices NaN"));
    if masked == 0 && poisoned == 0 {
        return None;
    }
    let mesh = m.mesh(PerVertex(&varyings));
    Some(frame_pass::<S, 3, _, _>(
        ctx,
        &m,
        &mesh,
        &VertexColor,
        cached,
    ))
}

/// Shading `name`'s passes (both paths) against the oracle (`base`, the
/// colour frame's passes, where nothing is masked; `None` for the colour
/// frame itself), then its strip renderers. Returns the passes.
fn check_shading<
    const S: u32,
    const N: usize,
    A: Attributes<N> + Copy,
    Fr: FragmentShader<N> + Copy,
>(
    ctx: &Ctx,
    o: &Owned,
    attrs: A,
    frag: Fr,
    needs: Needs,
    name: &str,
    base: Option<&[Pass; 2]>,
) -> [Pass; 2] {
    let mesh = o.mesh(attrs);
    let a = frame_pass::<S, N, _, _>(ctx, o, &mesh, &frag, false);
    let b = frame_pass::<S, N, _, _>(ctx, o, &mesh, &frag, true);
    assert_eq!(
        a.stats, b.stats,
        "{name}: submit_mesh and submit_mesh_cached count differently"
    );
    assert!(
        a.ids == b.ids,
        "{name}: submit_mesh and submit_mesh_cached cover differently"
    );
    assert!(
        a.depth == b.depth,
        "{name}: submit_mesh and submit_mesh_cached differ in depth"
    );
    assert!(
        a.rgb == b.rgb,
        "{name}: submit_mesh and submit_mesh_cached differ in colour"
    );
    for (k, (p, cached)) in [(&a, false), (&b, true)].into_iter().enumerate() {
        let own;
        let want = match oracle::<S>(ctx, o, needs, cached) {
            Some(x) => {
                own = x;
                &own
            }
            None => base.map_or(p, |x| &x[k]),
        };
        let path = if cached {
            "submit_mesh_cached"
        } else {
            "submit_mesh"
        };
        assert_eq!(
            p.stats, want.stats,
            "{name} ({path}): Stats differ from the colour frame's"
        );
        assert!(
            p.ids == want.ids,
            "{name} ({path}): ids differ from the colour frame's"
        );
        assert!(
            p.depth == want.depth,
            "{name} ({path}): depth differs from the colour frame's"
        );
    }
    strip_pass::<S, N, _, _>(ctx, o, &mesh, frag, [&a, &b], name);
    debug(|| format!("{name}: {:?}", a.stats));
    [a, b]
}

/// Whether `v` is finite and non-zero: the documented condition for a
/// light direction and the view.
fn ok_direction(v: [f32; 3]) -> bool {
    v.iter().all(|c| c.is_finite()) && v.iter().any(|&c| c != 0.0)
}

fn run_s<const S: u32, T: Texel + core::fmt::Debug>(
    input: &ShadeInput,
    ctx: &Ctx,
    o: &Owned,
    texels: &[T],
    stock_texels: &[T],
) {
    let r = &input.rest;
    let t = &r.tex;
    // Texture::new: exactly the documented errors.
    let (tw, th) = (t.width.0, t.height.0);
    let ok_side = |s: u32| (1..=MAX_TEXTURE_SIDE).contains(&s);
    let tex_ok = ok_side(tw) && ok_side(th) && texels.len() as u64 == tw as u64 * th as u64;
    let tex = Texture::new(texels, tw, th);
    match &tex {
        Ok(x) => {
            assert!(
                tex_ok,
                "Texture::new({tw}, {th}) with {} texels: Ok",
                texels.len()
            );
            assert_eq!(x.size(), (tw, th));
        }
        Err(e) => {
            assert!(
                !tex_ok,
                "Texture::new({tw}, {th}) with {} texels: {e:?}",
                texels.len()
            );
            assert_eq!(
                *e,
                Error::TextureSize {
                    width: tw,
                    height: th,
                    texels: texels.len()
                }
            );
        }
    }
    let filter = if t.bilinear {
        Filter::Bilinear
    } else {
        Filter::Nearest
    };
    let wrap = if t.clamp { Wrap::Clamp } else { Wrap::Repeat };
    let stock = input.blob.as_ref().is_some_and(|b| b.flags & 128 != 0);
    let tex = tex.ok().map(|x| x.with_sampling(filter, wrap));
    let tex = match tex {
        None if stock => Some(
            Texture::new(stock_texels, 32, 24)
                .expect("32 x 24")
                .with_sampling(filter, wrap),
        ),
        t => t,
    };

    // Lighting::new: exactly the documented errors.
    let lights: Vec<DirectionalLight> = r
        .lights
        .iter()
        .take(6)
        .map(|l| DirectionalLight {
            direction: v3(l.direction),
            color: l.color.map(|c| c.0),
        })
        .collect();
    let ambient = r.ambient.map(|c| c.0);
    let view = r.view.map(|c| c.0);
    let fin = |c: &[f32; 3]| c.iter().all(|v| v.is_finite());
    let light_ok = lights.len() <= MAX_LIGHTS
        && fin(&ambient)
        && ok_direction(view)
        && lights
            .iter()
            .all(|l| ok_direction([l.direction.x, l.direction.y, l.direction.z]) && fin(&l.color));
    let lighting = Lighting::new(ambient, &lights, v3(r.view));
    match &lighting {
        Ok(_) => assert!(
            light_ok,
            "Lighting::new({ambient:?}, {lights:?}, {view:?}): Ok"
        ),
        Err(e) => {
            assert_eq!(*e, Error::InvalidLighting);
            assert!(
                !light_ok,
                "Lighting::new({ambient:?}, {lights:?}, {view:?}): {e:?} for documented-valid lighting"
            );
        }
    }
    let lighting = match lighting {
        Err(_) if stock => {
            let sun = DirectionalLight {
                direction: Vec3::new(0.3, 0.8, 0.5),
                color: [0.9, 0.85, 0.8],
            };
            let fill = DirectionalLight {
                direction: Vec3::new(-0.6, -0.2, 0.4),
                color: [0.2, 0.25, 0.4],
            };
            Ok(Lighting::new([0.15; 3], &[sun, fill], Vec3::new(0.1, 0.2, 1.0)).expect("stock"))
        }
        l => l,
    };
    let material = Material {
        specular: r.specular.map(|c| c.0),
        shininess: r.shininess,
    };
    debug(|| {
        format!(
            "shading {}x{} S={S} rows {}..{}: {} tris, {} verts, normals {}, uvs {}, colours {} (mode {}), texture {:?}, lighting {}",
            ctx.config.width,
            ctx.config.height,
            ctx.y0,
            ctx.y1,
            o.indices.len(),
            o.positions.len(),
            o.normals.len(),
            o.uvs.len(),
            o.colors.len(),
            o.mode,
            tex.map(|x| x.size()),
            lighting.is_ok()
        )
    });

    let none = Needs {
        normals: false,
        uvs: false,
    };
    let base =
        check_shading::<S, 3, _, _>(ctx, o, o.colors(), VertexColor, none, "MeshColors", None);
    let base = Some(&base);
    if let Ok(l) = &lighting {
        let lit = LitColors {
            base: o.colors(),
            normals: &o.normals,
            lighting: l,
            material,
        };
        let nrm = Needs {
            normals: true,
            uvs: false,
        };
        check_shading::<S, 3, _, _>(ctx, o, lit, VertexColor, nrm, "LitColors", base);
        let phong = Phong {
            lighting: l,
            material,
            texture: NoTexture,
        };
        let cn = ColorNormal {
            color: o.colors(),
            normals: &o.normals,
        };
        check_shading::<S, 6, _, _>(ctx, o, cn, phong, nrm, "ColorNormal + Phong", base);
        if let Some(texture) = tex {
            if r.lit_uv {
                let cu = ColorUv {
                    color: lit,
                    uvs: &o.uvs,
                };
                let both = Needs {
                    normals: true,
                    uvs: true,
                };
                let f = Textured { texture };
                check_shading::<S, 5, _, _>(
                    ctx,
                    o,
                    cu,
                    f,
                    both,
                    "ColorUv<LitColors> + Textured",
                    base,
                );
            }
            let cun = ColorUvNormal {
                color: o.colors(),
                uvs: &o.uvs,
                normals: &o.normals,
            };
            let phong = Phong {
                lighting: l,
                material,
                texture,
            };
            let both = Needs {
                normals: true,
                uvs: true,
            };
            check_shading::<S, 8, _, _>(
                ctx,
                o,
                cun,
                phong,
                both,
                "ColorUvNormal + Phong<Texture>",
                base,
            );
        }
    }
    if let Some(texture) = tex {
        let cu = ColorUv {
            color: o.colors(),
            uvs: &o.uvs,
        };
        let uv = Needs {
            normals: false,
            uvs: true,
        };
        check_shading::<S, 5, _, _>(
            ctx,
            o,
            cu,
            Textured { texture },
            uv,
            "ColorUv + Textured",
            base,
        );
    }
}

/// Texels from a seed: `n` of them, a hash of the index.
fn texels<T>(n: usize, seed: u32, f: impl Fn(u32) -> T) -> Vec<T> {
    (0..n as u32)
        .map(|i| {
            let mut x = i.wrapping_mul(0x9e37_79b9) ^ seed;
            x ^= x >> 15;
            x = x.wrapping_mul(0x2c1b_3c6d);
            x ^= x >> 12;
            f(x)
        })
        .collect()
}

fn run_at<const S: u32>(input: &ShadeInput) {
    let r = &input.rest;
    let mut config = r.params.config();
    if let Some((w, h)) = input.blob.as_ref().and_then(|b| b.size) {
        config.width = w;
        config.height = h;
    }
    let valid = (1..=16384).contains(&config.width) && (1..=16384).contains(&config.height);
    let mut st = [SetupTriangle::<5>::EMPTY; 1];
    let f = Frame::<S, 5>::with_subpixel_bits(config, &mut st).map(|_| ());
    if !valid {
        assert_eq!(
            f,
            Err(Error::InvalidFrameSize {
                width: config.width,
                height: config.height
            })
        );
        return;
    }
    assert_eq!(f, Ok(()));
    let (w, h) = (config.width, config.height);
    let from_top = input.blob.as_ref().is_some_and(|b| b.flags & 64 != 0);
    let y0 = if from_top { 0 } else { r.window.0 as u32 % h };
    let max_rows = ((BUDGET / w as usize).max(1) as u32).min(h - y0);
    let y1 = if from_top {
        max_rows
    } else {
        y0 + 1 + r.window.1 as u32 % max_rows
    };
    let ctx = Ctx {
        config,
        y0,
        y1,
        strip: r.strip.max(1) as u32,
        extra_cache: r.extra_cache as usize % 4,
    };
    let o = Owned::new(input, w as f32 / h as f32);
    // Texel count: width * height, or off by the input's delta.
    let t = &r.tex;
    let want = (t.width.0 as u64 * t.height.0 as u64).min(1 << 16) as i64;
    let n = if t.delta.0.is_multiple_of(4) {
        (want + t.delta.1 as i64).clamp(0, 1 << 16)
    } else {
        want
    } as usize;
    if t.rgb565 {
        let tx = texels(n, t.seed, |x| {
            Rgb565::new(
                (x & 31) as u8,
                ((x >> 5) & 63) as u8,
                ((x >> 11) & 31) as u8,
            )
        });
        let stock = texels(32 * 24, t.seed, |x| {
            Rgb565::new(
                (x & 31) as u8,
                ((x >> 5) & 63) as u8,
                ((x >> 11) & 31) as u8,
            )
        });
        run_s::<S, Rgb565>(input, &ctx, &o, &tx, &stock);
    } else {
        let tx = texels(n, t.seed, |x| {
            Rgb888::new(x as u8, (x >> 8) as u8, (x >> 16) as u8)
        });
        let stock = texels(32 * 24, t.seed, |x| {
            Rgb888::new(x as u8, (x >> 8) as u8, (x >> 16) as u8)
        });
        run_s::<S, Rgb888>(input, &ctx, &o, &tx, &stock);
    }
}

/// The `shading` target.
pub fn run_shading(input: &ShadeInput) {
    if input.rest.params.s8 {
        run_at::<8>(input)
    } else {
        run_at::<4>(input)
    }
}
