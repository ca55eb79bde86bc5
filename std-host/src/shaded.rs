//! Lit and textured rendering of one model: what `render --obj` draws.
//!
//! Design note: a [`ShadedModel`] is a mesh with what its file describes
//! (normals, texture coordinates, a diffuse colour per triangle from its
//! materials, one texture); [`render_shaded`] draws it with the core's
//! shading types, so the mode is a compile-time choice here as on a
//! microcontroller:
//!
//! | `--shading` | no texture | texture |
//! |---|---|---|
//! | `flat` | lit per triangle (face normal), `N = 3`, `VertexColor` | `ColorUv` + `Textured`, `N = 5` |
//! | `gouraud` | `LitColors` (per vertex), `N = 3`, `VertexColor` | `ColorUv<LitColors>` + `Textured`, `N = 5` |
//! | `phong` | `ColorNormal` + `Phong`, `N = 6` | `ColorUvNormal` + textured `Phong`, `N = 8` |
//!
//! The light: ambient 0.15, a directional key light (0.8) given in camera
//! space (x right, y up, z towards the viewer; default [`DEFAULT_LIGHT`],
//! above and to the left of the viewer) and a fill light (0.3,
//! [`FILL_LIGHT`], from the right), turned into world space once per frame
//! with the camera's basis; the model is drawn
//! with the identity model matrix, so world space is object space and no
//! normal is transformed. The viewer is at infinity along the view axis
//! (Blinn-Phong half vector per light, see `microraster::shade`).
//!
//! The frame is set up once (one core `Frame`, storage grown on
//! `StorageFull`), then strips are drawn on the worker threads from a
//! shared queue, as in [`crate::render`]; the image is identical for any
//! thread count and strip height.

use crate::pipeline::for_each_tile;
use crate::render::{DepthImage, DepthKind, RenderOptions, Rendered, Timings, BACKGROUND};
use crate::scene::{look_at, up_for};
use microraster::math::radians;
use microraster::pixelcolor::{Rgb888, RgbColor};
use microraster::prelude::*;
use microraster::shade::{
    ColorNormal, ColorUv, ColorUvNormal, DirectionalLight, Filter, Lighting, LitColors, Material,
    NoTexture, Phong, Texture, Textured, Wrap,
};
use microraster::{
    Attributes, BoundingSphere, Config, DepthWord, Error, FragmentShader, Frame, Mat4, Mesh,
    MeshColors, NoDepth, PixelFormat, ProcessedVertex, RasterMode, SetupTriangle, Stats,
    TriangleId, Vec3, VertexColor,
};
use std::time::Instant;

/// The key light's direction in camera space when `--light` is not given:
/// from above, to the left and behind the viewer.
pub const DEFAULT_LIGHT: [f32; 3] = [-0.4, 0.6, 1.0];

/// Ambient light, per channel.
pub const AMBIENT: f32 = 0.15;

/// The key light's intensity.
pub const KEY: f32 = 0.8;

/// A weaker fill light from the other side (camera space: right, a little
/// below, towards the viewer), so faces turned away from the key are not
/// left to the ambient alone.
pub const FILL_LIGHT: [f32; 3] = [0.7, -0.2, 0.6];

/// The fill light's intensity.
pub const FILL: f32 = 0.3;

/// How a model is lit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ShadingMode {
    /// One lit colour per triangle (face normals).
    Flat,
    /// Lit per vertex, interpolated.
    Gouraud,
    /// Lit per pixel from interpolated normals.
    #[default]
    Phong,
}

/// A texture in memory: `width * height` texels, row 0 first.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureData {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Texels, row 0 (top of the image) first.
    pub texels: Vec<Rgb888>,
}

/// A model with what its file describes.
#[derive(Clone, Debug, PartialEq)]
pub struct ShadedModel {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles.
    pub indices: Vec<[u32; 3]>,
    /// Unit normals, one per vertex.
    pub normals: Vec<Vec3>,
    /// Texture coordinates per vertex, `v = 0` at the texture's first
    /// row; `None` if the model has none.
    pub uvs: Option<Vec<[f32; 2]>>,
    /// Diffuse colour per triangle (the material's `Kd`).
    pub diffuse: Vec<Rgb888>,
    /// The model's texture (`map_Kd`), if any.
    pub texture: Option<TextureData>,
    /// The highlight.
    pub material: Material,
}

/// What to draw the model with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadingOptions {
    /// Flat, Gouraud or Phong.
    pub mode: ShadingMode,
    /// Towards the key light, in camera space.
    pub light: [f32; 3],
    /// Whether to use the model's texture (if it has one and UVs).
    pub texture: bool,
    /// Bilinear (else nearest) texture filtering.
    pub bilinear: bool,
}

impl Default for ShadingOptions {
    fn default() -> Self {
        ShadingOptions {
            mode: ShadingMode::Phong,
            light: DEFAULT_LIGHT,
            texture: true,
            bilinear: true,
        }
    }
}

/// The camera of a render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: [f32; 3],
    /// Point looked at.
    pub target: [f32; 3],
    /// Vertical field of view in degrees.
    pub fov_y_deg: f32,
}

/// The key light and view direction in world space, from camera space.
fn world_lighting(camera: &Camera, light: [f32; 3]) -> Result<Lighting, String> {
    let v = Vec3::from_array;
    let (eye, target) = (v(camera.eye), v(camera.target));
    let f = (target - eye).normalize();
    let r = f.cross(v(up_for(camera.eye, camera.target))).normalize();
    let u = r.cross(f);
    let world = |c: [f32; 3]| r * c[0] + u * c[1] - f * c[2];
    let key = DirectionalLight {
        direction: world(light),
        color: [KEY; 3],
    };
    let fill = DirectionalLight {
        direction: world(FILL_LIGHT),
        color: [FILL; 3],
    };
    Lighting::new([AMBIENT; 3], &[key, fill], -f)
        .map_err(|e| format!("--light {light:?}: {e} (give a non-zero finite direction)"))
}

/// The clip-space transform of `model` seen by `camera`, with near and
/// far planes around its bounding sphere (with `inv_w`, 1/w depth from
/// the same near plane: `Mat4::perspective_inv_w`, no far plane).
fn mvp(model: &ShadedModel, camera: &Camera, aspect: f32, inv_w: bool) -> Result<Mat4, String> {
    let view = look_at(camera.eye, camera.target)?;
    let bounds = BoundingSphere::from_points(&model.positions);
    let (eye, target) = (
        Vec3::from_array(camera.eye),
        Vec3::from_array(camera.target),
    );
    let dist = (target - eye).length();
    let radius = bounds.map(|b| b.radius).unwrap_or(1.0);
    let near = (dist - 2.0 * radius).max(dist * 0.01).max(1e-4);
    let far = (dist + 2.0 * radius).max(near * 2.0);
    let fov = radians(camera.fov_y_deg);
    Ok(crate::scene::projection(inv_w, fov, aspect, near, far) * view)
}

/// Diffuse colours lit per triangle with its face normal.
fn flat_colors(model: &ShadedModel, lighting: &Lighting) -> Vec<Rgb888> {
    model
        .indices
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let p = |k: usize| {
                model
                    .positions
                    .get(t[k] as usize)
                    .copied()
                    .unwrap_or(Vec3::ZERO)
            };
            let n = (p(1) - p(0)).cross(p(2) - p(0)).normalize();
            let base = model.diffuse.get(i).copied().unwrap_or(Rgb888::WHITE);
            let c = lighting.shade(
                [base.r() as f32, base.g() as f32, base.b() as f32],
                &model.material,
                n,
            );
            Rgb888::new((c[0] + 0.5) as u8, (c[1] + 0.5) as u8, (c[2] + 0.5) as u8)
        })
        .collect()
}

/// Renders `model` from `camera` as `opts` and `shading` say.
pub fn render_shaded(
    model: &ShadedModel,
    camera: &Camera,
    opts: &RenderOptions,
    shading: &ShadingOptions,
) -> Result<Rendered, String> {
    match opts.subpixel {
        8 => render_s::<8>(model, camera, opts, shading),
        4 => render_s::<4>(model, camera, opts, shading),
        s => Err(format!("unsupported subpixel precision {s} (use 4 or 8)")),
    }
}

fn render_s<const S: u32>(
    model: &ShadedModel,
    camera: &Camera,
    opts: &RenderOptions,
    shading: &ShadingOptions,
) -> Result<Rendered, String> {
    // The camera first: its errors (eye at the target) are not the light's.
    let aspect = opts.width as f32 / opts.height as f32;
    let mvp = mvp(model, camera, aspect, opts.inv_w)?;
    let lighting = world_lighting(camera, shading.light)?;
    let texels;
    let texture = match (&model.texture, &model.uvs, shading.texture) {
        (Some(t), Some(_), true) => {
            texels = t;
            let filter = if shading.bilinear {
                Filter::Bilinear
            } else {
                Filter::Nearest
            };
            Some(
                Texture::new(&texels.texels, t.width, t.height)
                    .map_err(|e| format!("texture: {e}"))?
                    .with_sampling(filter, Wrap::Repeat),
            )
        }
        _ => None,
    };
    let uvs = model.uvs.as_deref().unwrap_or(&[]);
    let diffuse = MeshColors::PerTriangle(&model.diffuse);
    let material = model.material;
    let job = Job {
        model,
        mvp: &mvp,
        opts,
    };
    match (shading.mode, texture) {
        (ShadingMode::Flat, None) => {
            let lit = flat_colors(model, &lighting);
            job.run::<S, 3, _, _>(MeshColors::PerTriangle(&lit), &VertexColor)
        }
        (ShadingMode::Flat, Some(texture)) => {
            let lit = flat_colors(model, &lighting);
            let attrs = ColorUv {
                color: MeshColors::PerTriangle(&lit),
                uvs,
            };
            job.run::<S, 5, _, _>(attrs, &Textured { texture })
        }
        (ShadingMode::Gouraud, tex) => {
            let lit = LitColors {
                base: diffuse,
                normals: &model.normals,
                lighting: &lighting,
                material,
            };
            match tex {
                None => job.run::<S, 3, _, _>(lit, &VertexColor),
                Some(texture) => {
                    job.run::<S, 5, _, _>(ColorUv { color: lit, uvs }, &Textured { texture })
                }
            }
        }
        (ShadingMode::Phong, None) => {
            let attrs = ColorNormal {
                color: diffuse,
                normals: &model.normals,
            };
            let phong = Phong {
                lighting: &lighting,
                material,
                texture: NoTexture,
            };
            job.run::<S, 6, _, _>(attrs, &phong)
        }
        (ShadingMode::Phong, Some(texture)) => {
            let attrs = ColorUvNormal {
                color: diffuse,
                uvs,
                normals: &model.normals,
            };
            let phong = Phong {
                lighting: &lighting,
                material,
                texture,
            };
            job.run::<S, 8, _, _>(attrs, &phong)
        }
    }
}

/// One render of a model with a transform.
struct Job<'a> {
    model: &'a ShadedModel,
    mvp: &'a Mat4,
    opts: &'a RenderOptions,
}

impl Job<'_> {
    /// Sets the model up once with attributes `attrs` and draws it with
    /// `fragment`.
    fn run<const S: u32, const N: usize, A, F>(
        &self,
        attrs: A,
        fragment: &F,
    ) -> Result<Rendered, String>
    where
        A: Attributes<N> + Sync,
        F: FragmentShader<N> + Sync,
    {
        let (model, opts) = (self.model, self.opts);
        let (w, h) = (opts.width, opts.height);
        let mut config = Config::new(w, h);
        config.cull = opts.cull;
        config.detail = opts.detail;
        if opts.inv_w {
            config.depth_func = microraster::DepthFunc::Greater;
        }
        let mesh = Mesh {
            positions: &model.positions,
            indices: &model.indices,
            attributes: attrs,
            bounds: BoundingSphere::from_points(&model.positions),
        };
        let t0 = Instant::now();
        let mut cache = vec![ProcessedVertex::EMPTY; model.positions.len()];
        if opts.mode == RasterMode::Clipless {
            // No frame (it stores snapped triangles only): the vertices
            // processed once, the mesh submitted again to a strip renderer
            // per strip or tile.
            config.mode = RasterMode::Clipless;
            let (mut row, mut none) = (vec![BACKGROUND; w as usize], NoDepth);
            let probe = microraster::StripRenderer::<_, _, S, N, &F>::with_shader(
                config, 0, 1, &mut row, &mut none, fragment,
            )
            .map_err(|e| e.to_string())?;
            probe.process_vertices(self.mvp, &model.positions, &mut cache);
            let stats = std::sync::Mutex::new(Stats::default());
            let src = Immediate::<S, N, A, F> {
                config,
                mesh: &mesh,
                cache: &cache,
                fragment,
                stats: &stats,
            };
            let setup_ms = t0.elapsed().as_secs_f64() * 1e3;
            return self.draw_all(&src, setup_ms, || {
                stats.lock().map(|s| *s).unwrap_or_default()
            });
        }
        let mut capacity = Frame::<S>::storage_for(model.indices.len());
        let mut storage;
        let frame = loop {
            storage = vec![SetupTriangle::<N>::EMPTY; capacity];
            let mut frame = Frame::<S, N>::with_subpixel_bits(config, &mut storage)
                .map_err(|e| e.to_string())?;
            match frame.submit_mesh_cached(&mesh, self.mvp, 0, &mut cache) {
                Ok(()) => break frame,
                Err(Error::StorageFull { needed, .. }) => capacity = capacity + needed + 64,
                Err(e) => return Err(e.to_string()),
            }
        };
        let stats: Stats = frame.stats();
        let setup_ms = t0.elapsed().as_secs_f64() * 1e3;
        self.draw_all(
            &SetUp {
                frame: &frame,
                fragment,
            },
            setup_ms,
            || stats,
        )
    }

    /// Draws the colour image (and the id image if asked) from `src`;
    /// `stats` gives the counters once the colour image is drawn.
    fn draw_all<R>(
        &self,
        src: &R,
        setup_ms: f64,
        stats: impl FnOnce() -> Stats,
    ) -> Result<Rendered, String>
    where
        R: DrawRect<Rgb888> + DrawRect<TriangleId>,
    {
        let opts = self.opts;
        let (w, h) = (opts.width, opts.height);
        let len = w as usize * h as usize;
        let (threads, rows) = (opts.threads.max(1), opts.strip_rows.max(1));
        let tile = (opts.tile_width, rows);
        let kind = (opts.depth, opts.inv_w);
        let t1 = Instant::now();
        let mut color = vec![BACKGROUND; len];
        let (depth, pixels_written) = draw(src, &mut color, kind, BACKGROUND, tile, threads)?;
        let raster_ms = t1.elapsed().as_secs_f64() * 1e3;
        let stats = stats();
        let t2 = Instant::now();
        let ids = if opts.ids {
            let mut ids = vec![TriangleId(0); len];
            draw(src, &mut ids, kind, TriangleId(0), tile, threads)?;
            Some(ids.into_iter().map(|t| t.0).collect())
        } else {
            None
        };
        let ids_ms = t2.elapsed().as_secs_f64() * 1e3;
        Ok(Rendered {
            width: w,
            height: h,
            rgb: color.iter().flat_map(|c| [c.r(), c.g(), c.b()]).collect(),
            ids,
            depth,
            stats,
            pixels_written,
            timings: Timings {
                setup_ms,
                raster_ms,
                ids_ms,
            },
        })
    }
}

/// Draws one rectangle of the image into buffers that hold exactly it.
trait DrawRect<C>: Sync {
    /// The image's width.
    fn width(&self) -> u32;

    /// Draws `rect` into `color` and `depth`; returns the pixels written.
    fn draw<D: DepthBuffer + ?Sized>(
        &self,
        rect: [u32; 4],
        color: &mut [C],
        depth: &mut D,
    ) -> Result<u64, Error>;
}

/// A frame set up once, drawn rectangle by rectangle.
struct SetUp<'a, 'f, const S: u32, const N: usize, F> {
    frame: &'a Frame<'f, S, N>,
    fragment: &'a F,
}

impl<C: PixelFormat, const S: u32, const N: usize, F> DrawRect<C> for SetUp<'_, '_, S, N, F>
where
    F: FragmentShader<N> + Sync,
{
    fn width(&self) -> u32 {
        self.frame.config().width
    }

    fn draw<D: DepthBuffer + ?Sized>(
        &self,
        rect: [u32; 4],
        color: &mut [C],
        depth: &mut D,
    ) -> Result<u64, Error> {
        Ok(self
            .frame
            .render_rect_shaded(rect, color, depth, self.fragment)?
            .pixels_written)
    }
}

/// The clipless mode: the mesh submitted again to a strip renderer for
/// each rectangle, from vertices processed once (counters summed over
/// the rectangles of the colour image).
struct Immediate<'a, const S: u32, const N: usize, A, F> {
    config: Config,
    mesh: &'a Mesh<'a, A>,
    cache: &'a [ProcessedVertex],
    fragment: &'a F,
    stats: &'a std::sync::Mutex<Stats>,
}

impl<C: PixelFormat, const S: u32, const N: usize, A, F> DrawRect<C> for Immediate<'_, S, N, A, F>
where
    A: Attributes<N> + Sync,
    F: FragmentShader<N> + Sync,
{
    fn width(&self) -> u32 {
        self.config.width
    }

    fn draw<D: DepthBuffer + ?Sized>(
        &self,
        rect: [u32; 4],
        color: &mut [C],
        depth: &mut D,
    ) -> Result<u64, Error> {
        let mut r = microraster::StripRenderer::<C, D, S, N, &F>::with_shader_rect(
            self.config,
            rect,
            color,
            depth,
            self.fragment,
        )?;
        r.submit_processed_mesh(self.mesh, 0, self.cache)?;
        if C::SHADED {
            if let Ok(mut s) = self.stats.lock() {
                *s += r.stats();
            }
        }
        Ok(r.render_stats().pixels_written)
    }
}

/// Draws `src` into `color` (every strip or tile cleared to `clear`
/// first) with a new depth buffer of `kind`, cleared to the far plane, or
/// with `reversed` (1/w depth) to 0; returns the depth image and the
/// pixels written.
fn draw<C, R>(
    src: &R,
    color: &mut [C],
    (kind, reversed): (DepthKind, bool),
    clear: C,
    tile: (u32, u32),
    threads: usize,
) -> Result<(DepthImage, u64), String>
where
    C: PixelFormat + Send + Sync,
    R: DrawRect<C>,
{
    let len = color.len();
    macro_rules! with {
        ($t:ty, $image:path) => {{
            let z: $t = if reversed {
                <$t as DepthWord>::NEAR
            } else {
                <$t as DepthWord>::FAR
            };
            let mut d = vec![z; len];
            let px = draw_with(src, color, Some((&mut d[..], z)), clear, tile, threads)?;
            ($image(d), px)
        }};
    }
    Ok(match kind {
        DepthKind::U16 => with!(u16, DepthImage::U16),
        DepthKind::U32 => with!(u32, DepthImage::U32),
        DepthKind::F32 => with!(microraster::DepthF32, DepthImage::F32),
        DepthKind::None => {
            let px = draw_with::<C, R, u32>(src, color, None, clear, tile, threads)?;
            (DepthImage::None, px)
        }
    })
}

/// [`draw`] into a depth buffer of `T` words cleared to the given word
/// (or none).
fn draw_with<C, R, T>(
    src: &R,
    color: &mut [C],
    depth: Option<(&mut [T], T)>,
    clear: C,
    (tile_w, rows): (u32, u32),
    threads: usize,
) -> Result<u64, String>
where
    C: PixelFormat + Send + Sync,
    R: DrawRect<C>,
    T: DepthWord,
{
    let tile = (tile_w as usize, rows as usize);
    let (depth, z) = match depth {
        Some((d, z)) => (Some(d), z),
        None => (None, T::FAR),
    };
    let width = src.width() as usize;
    let draw_tile = |_, rect: [u32; 4], c: &mut [C], d: Option<&mut [T]>| -> Result<u64, Error> {
        c.fill(clear);
        match d {
            Some(d) => {
                d.fill(z);
                src.draw(rect, c, d)
            }
            None => src.draw(rect, c, &mut NoDepth),
        }
    };
    for_each_tile(color, depth, width, tile, threads, false, draw_tile).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> ShadedModel {
        let positions = vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ];
        let indices = vec![[0, 1, 2], [0, 2, 3]];
        let normals = vec![Vec3::new(0.0, 0.0, 1.0); 4];
        ShadedModel {
            positions,
            indices,
            normals,
            uvs: Some(vec![[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]),
            diffuse: vec![Rgb888::new(200, 180, 160); 2],
            texture: Some(TextureData {
                width: 2,
                height: 2,
                texels: vec![
                    Rgb888::new(255, 0, 0),
                    Rgb888::new(0, 255, 0),
                    Rgb888::new(0, 0, 255),
                    Rgb888::new(255, 255, 255),
                ],
            }),
            material: Material {
                specular: [0.3; 3],
                shininess: 16,
            },
        }
    }

    fn opts(threads: usize, strip_rows: u32) -> RenderOptions {
        RenderOptions {
            width: 64,
            height: 48,
            cull: microraster::CullMode::Back,
            detail: 0,
            depth: DepthKind::U16,
            subpixel: 8,
            threads,
            strip_rows,
            tile_width: 0,
            ids: true,
            mode: microraster::RasterMode::Clipping,
            inv_w: false,
            occlusion: crate::render::Occlusion::Off,
        }
    }

    const CAMERA: Camera = Camera {
        eye: [0.3, 0.4, 3.0],
        target: [0.0, 0.0, 0.0],
        fov_y_deg: 60.0,
    };

    #[test]
    fn every_mode_has_the_same_coverage_and_any_split_the_same_image() {
        let model = quad();
        let mut first_ids = None;
        for mode in [ShadingMode::Flat, ShadingMode::Gouraud, ShadingMode::Phong] {
            for texture in [false, true] {
                let s = ShadingOptions {
                    mode,
                    texture,
                    ..ShadingOptions::default()
                };
                let base = render_shaded(&model, &CAMERA, &opts(1, 48), &s).unwrap();
                assert!(base.pixels_written > 500, "{mode:?}");
                match &first_ids {
                    None => first_ids = Some(base.ids.clone()),
                    Some(ids) => assert_eq!(ids, &base.ids, "{mode:?} {texture}"),
                }
                for (t, r) in [(2, 5), (3, 1)] {
                    let other = render_shaded(&model, &CAMERA, &opts(t, r), &s).unwrap();
                    assert_eq!(base.rgb, other.rgb, "{mode:?} {texture} {t} {r}");
                    assert_eq!(base.depth, other.depth);
                }
            }
        }
    }

    #[test]
    fn a_zero_light_is_an_error() {
        let s = ShadingOptions {
            light: [0.0; 3],
            ..ShadingOptions::default()
        };
        let e = render_shaded(&quad(), &CAMERA, &opts(1, 8), &s).unwrap_err();
        assert!(e.contains("--light"), "{e}");
    }
}
