//! Shading: what a covered pixel's colour is made of, chosen at compile
//! time.
//!
//! Design note: coverage and depth never depend on shading (the id
//! buffer is the same whatever the shader). A triangle carries `N`
//! *varyings* per vertex (`f32`), interpolated perspective-correct over
//! it; two traits split the work:
//!
//! - an [`Attributes<N>`] source gives each mesh vertex its varyings in the
//!   vertex stage: [`MeshColors`] (a colour, `N = 3`), [`LitColors`]
//!   (Lambert plus Blinn-Phong lighting per vertex, Gouraud, `N = 3`),
//!   [`ColorUv`] (colour and texture coordinates, `N = 5`),
//!   [`ColorNormal`] (`N = 6`) and [`ColorUvNormal`] (`N = 8`) for
//!   lighting per pixel;
//! - a [`FragmentShader<N>`] turns a pixel's interpolated varyings into a
//!   colour: [`VertexColor`] (the varyings are the colour), [`Textured`]
//!   (texture times colour), [`Phong`] (lit per pixel, optionally
//!   textured).
//!
//! Both are type parameters, so a scene links only the shading it uses: an
//! unlit, untextured frame (`N = 3`, [`VertexColor`]) contains no lighting,
//! no square root and no texture code.
//!
//! Lighting is ambient plus up to [`MAX_LIGHTS`] directional lights, with
//! the viewer at infinity (one view direction per object, so the
//! Blinn-Phong half vector is one per light): normals, light and view
//! directions must be in one space. Object space is cheapest: transform
//! the lights into it once per object (for a rigid model, by the transpose
//! of its rotation) instead of every normal.
//!
//! Colour channels are `0.0..=255.0` in varyings and `0.0..=1.0` in light
//! and material factors. Texture coordinates `(u, v)` address texel
//! `(u * width, v * height)`, row 0 first (`v = 0` is the first row of the
//! slice: flip OBJ's `v`, which points up, when loading).

use crate::config::Error;
use crate::math::{fx, Vec3};
use crate::mesh::{rgb_f32, MeshColors};
use embedded_graphics_core::pixelcolor::{Rgb565, Rgb888, RgbColor};

/// Where a mesh's varyings come from, per vertex, in the vertex stage.
///
/// `N` is the number of varyings; the layout is the implementor's (and
/// must match the [`FragmentShader`] that reads them).
pub trait Attributes<const N: usize> {
    /// Whether every value [`Attributes::get`] returns is finite for any
    /// input (colours, clamped lighting): then the pipeline does not check.
    /// Sources of the caller's floats (texture coordinates, raw varyings)
    /// leave it `false`, and a triangle with a NaN or infinite varying is
    /// counted in `Stats::rejected_nonfinite` by every submission path.
    const FINITE: bool = false;

    /// Whether [`Attributes::detail_fill`] may give a fill (`false`, the
    /// default: detail culling drops, and what a submission may store is
    /// bounded without boxes). Implementors that override `detail_fill`
    /// set it; where it is `false` the fill is never asked for.
    const DETAIL_FILL: bool = false;

    /// Whether every triangle of a mesh with `triangles` triangles and
    /// `vertices` vertices has its varyings, so [`Attributes::has`] need
    /// not be asked per triangle.
    fn complete(&self, triangles: usize, vertices: usize) -> bool;
    /// Whether triangle `tri` with vertex indices `idx` has its varyings
    /// (a triangle without is counted as a bad index).
    fn has(&self, tri: usize, idx: [u32; 3]) -> bool;
    /// The varyings of vertex `vertex` in triangle `tri`; asked only where
    /// [`Attributes::has`] (or [`Attributes::complete`]) said yes, and
    /// only for triangles that survive culling. Never panics (zeros where
    /// out of range).
    fn get(&self, tri: usize, vertex: u32) -> [f32; N];

    /// The varyings of the box that detail culling draws in place of a
    /// dropped object or cluster node ([`Detail::screen_box`]), whose
    /// triangles are `triangles` (indices into the mesh's triangles: all of
    /// them for an object; a node's, for a per-node colour), or `None`
    /// (the default) to drop it and draw nothing; asked only where
    /// [`Attributes::DETAIL_FILL`] is set. [`DetailFill`] gives a
    /// mesh's attributes one fill; a fill that is not finite draws
    /// nothing. A box covers its sphere's projection and so reaches
    /// beyond it: under an [`Occluder`], submit an object that may become
    /// a box unbounded (`sphere: None`).
    ///
    /// [`Occluder`]: crate::Occluder
    /// [`Detail::screen_box`]: crate::Detail::screen_box
    #[inline(always)]
    fn detail_fill(&self, triangles: core::ops::Range<usize>) -> Option<[f32; N]> {
        let _ = triangles;
        None
    }
}

/// Attributes `A` with the varyings of the box detail culling draws in
/// place of what it drops (for [`VertexColor`]: its colour, say the
/// mesh's mean colour), [`Attributes::detail_fill`]. Everything else is
/// `A`'s.
#[derive(Clone, Copy, Debug)]
pub struct DetailFill<A, const N: usize> {
    /// The mesh's attributes.
    pub attributes: A,
    /// The box's varyings.
    pub fill: [f32; N],
}

impl<const N: usize, A: Attributes<N>> Attributes<N> for DetailFill<A, N> {
    const FINITE: bool = A::FINITE;
    const DETAIL_FILL: bool = true;

    #[inline]
    fn complete(&self, triangles: usize, vertices: usize) -> bool {
        self.attributes.complete(triangles, vertices)
    }
    #[inline]
    fn has(&self, tri: usize, idx: [u32; 3]) -> bool {
        self.attributes.has(tri, idx)
    }
    #[inline]
    fn get(&self, tri: usize, vertex: u32) -> [f32; N] {
        self.attributes.get(tri, vertex)
    }
    #[inline]
    fn detail_fill(&self, _: core::ops::Range<usize>) -> Option<[f32; N]> {
        Some(self.fill)
    }
}

impl Attributes<3> for MeshColors<'_> {
    const FINITE: bool = true;

    #[inline]
    fn complete(&self, triangles: usize, vertices: usize) -> bool {
        match *self {
            MeshColors::Uniform(_) => true,
            MeshColors::PerTriangle(cs) => cs.len() >= triangles,
            MeshColors::PerVertex(cs) => cs.len() >= vertices,
        }
    }
    #[inline]
    fn has(&self, tri: usize, idx: [u32; 3]) -> bool {
        match *self {
            MeshColors::Uniform(_) => true,
            MeshColors::PerTriangle(cs) => tri < cs.len(),
            MeshColors::PerVertex(cs) => idx.iter().all(|&k| (k as usize) < cs.len()),
        }
    }
    #[cfg_attr(target_pointer_width = "64", inline(always))]
    #[cfg_attr(not(target_pointer_width = "64"), inline)]
    fn get(&self, tri: usize, vertex: u32) -> [f32; 3] {
        rgb_f32(match *self {
            MeshColors::Uniform(c) => c,
            MeshColors::PerTriangle(cs) => cs.get(tri).copied().unwrap_or_default(),
            MeshColors::PerVertex(cs) => cs.get(vertex as usize).copied().unwrap_or_default(),
        })
    }
}

/// Per-vertex varyings given as they are, one `[f32; N]` per vertex.
#[derive(Clone, Copy, Debug)]
pub struct PerVertex<'a, const N: usize>(pub &'a [[f32; N]]);

impl<const N: usize> Attributes<N> for PerVertex<'_, N> {
    #[inline]
    fn complete(&self, _: usize, vertices: usize) -> bool {
        self.0.len() >= vertices
    }
    #[inline]
    fn has(&self, _: usize, idx: [u32; 3]) -> bool {
        idx.iter().all(|&k| (k as usize) < self.0.len())
    }
    #[inline]
    fn get(&self, _: usize, vertex: u32) -> [f32; N] {
        self.0.get(vertex as usize).copied().unwrap_or([0.0; N])
    }
}

/// A vertex's varyings given directly, for
/// [`Submit::submit_clip_triangle`](crate::Submit::submit_clip_triangle):
/// a colour for the default `N = 3`, or the array itself.
pub trait Varyings<const N: usize>: Copy {
    /// The varyings.
    fn varyings(self) -> [f32; N];
}

impl Varyings<3> for Rgb888 {
    #[inline]
    fn varyings(self) -> [f32; 3] {
        rgb_f32(self)
    }
}

impl<const N: usize> Varyings<N> for [f32; N] {
    #[inline]
    fn varyings(self) -> [f32; N] {
        self
    }
}

/// Turns a pixel's interpolated varyings into its colour.
pub trait FragmentShader<const N: usize> {
    /// The colour of a pixel of triangle `id` with varyings `v`. A
    /// triangle's pixels are shaded row by row, left to right; one whose
    /// vertices carry equal varyings is shaded once per strip
    /// ([`FragmentShader::shade_flat`]).
    fn shade(&self, v: &[f32; N], id: u32) -> Rgb888;

    /// The colour of a flat triangle (every vertex carries `v`); `rgb` is
    /// the first three varyings rounded as [`VertexColor`] shades them,
    /// computed once at setup (black for `N < 3`). By default
    /// [`FragmentShader::shade`].
    #[inline(always)]
    fn shade_flat(&self, v: &[f32; N], rgb: Rgb888, id: u32) -> Rgb888 {
        let _ = rgb;
        self.shade(v, id)
    }
}

/// A shader by reference (e.g. one shared by the strip renderers of many
/// threads): the same colours.
impl<const N: usize, F: FragmentShader<N> + ?Sized> FragmentShader<N> for &F {
    #[inline(always)]
    fn shade(&self, v: &[f32; N], id: u32) -> Rgb888 {
        (**self).shade(v, id)
    }
    #[inline(always)]
    fn shade_flat(&self, v: &[f32; N], rgb: Rgb888, id: u32) -> Rgb888 {
        (**self).shade_flat(v, rgb, id)
    }
}

/// The varyings are the colour: red, green, blue in `0.0..=255.0`
/// (rounded to nearest). The default shader; flat and Gouraud shading,
/// lit per vertex when the attributes are [`LitColors`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct VertexColor;

impl FragmentShader<3> for VertexColor {
    #[inline(always)]
    fn shade(&self, v: &[f32; 3], _: u32) -> Rgb888 {
        Rgb888::new(to_u8(v[0]), to_u8(v[1]), to_u8(v[2]))
    }
    #[inline(always)]
    fn shade_flat(&self, _: &[f32; 3], rgb: Rgb888, _: u32) -> Rgb888 {
        rgb
    }
}

/// `0.0..=255.0` to a channel, rounded to nearest (saturating).
#[inline(always)]
fn to_u8(f: f32) -> u8 {
    (f + 0.5) as u8
}

/// The most directional lights a [`Lighting`] holds.
pub const MAX_LIGHTS: usize = 4;

/// A light at infinity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    /// Direction towards the light (need not be unit length).
    pub direction: Vec3,
    /// Intensity per channel (1.0 is full).
    pub color: [f32; 3],
}

/// One light, prepared: unit direction and Blinn-Phong half vector.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Prepared {
    l: Vec3,
    h: Vec3,
    color: [f32; 3],
}

/// Ambient light plus up to [`MAX_LIGHTS`] directional lights, seen from
/// an infinitely distant viewer, prepared once per object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lighting {
    ambient: [f32; 3],
    lights: [Prepared; MAX_LIGHTS],
    count: usize,
}

/// A surface's lighting response; the diffuse colour comes from the
/// varyings (or the texture).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Specular colour, `0.0..=1.0` per channel (`Ks`); zero for none.
    pub specular: [f32; 3],
    /// Blinn-Phong exponent (`Ns`, rounded), `0..=1024`.
    pub shininess: u16,
}

impl Material {
    /// Diffuse only: no highlight.
    pub const MATTE: Material = Material {
        specular: [0.0; 3],
        shininess: 0,
    };
}

/// `v / |v|`, or `None` for a zero or non-finite vector. Outside the
/// range where its square is safe, the vector is scaled by its largest
/// component first, so no finite non-zero vector under- or overflows.
#[inline]
fn normalize(v: Vec3) -> Option<Vec3> {
    let n2 = v.dot(v);
    // Only finite vectors pass (a NaN or infinite component makes `n2`
    // NaN or infinite).
    if n2 > 1e-30 && n2 < 1e30 {
        let inv = 1.0 / fx::sqrt(n2);
        return Some(Vec3::new(v.x * inv, v.y * inv, v.z * inv));
    }
    // (`f32::max` below would drop a NaN component.)
    if !v.is_finite() {
        return None;
    }
    let m = v.x.abs().max(v.y.abs()).max(v.z.abs());
    if !(m > 0.0 && m.is_finite()) {
        return None;
    }
    let u = Vec3::new(v.x / m, v.y / m, v.z / m);
    // 1 <= |u|^2 <= 3.
    let inv = 1.0 / fx::sqrt(u.dot(u));
    Some(Vec3::new(u.x * inv, u.y * inv, u.z * inv))
}

/// `v` clamped to `0.0..=255.0`, NaN to 0.
#[inline(always)]
fn channel(v: f32) -> f32 {
    if v >= 0.0 {
        v.min(255.0)
    } else {
        0.0
    }
}

/// `x^n` by squaring (`n <= 1024`: at most 21 multiplications).
#[inline]
fn powi(mut x: f32, mut n: u32) -> f32 {
    let mut r = 1.0f32;
    while n > 0 {
        if n & 1 != 0 {
            r *= x;
        }
        x *= x;
        n >>= 1;
    }
    r
}

impl Lighting {
    /// Ambient `ambient` (per channel, `0.0..=1.0`), the directional
    /// `lights` and the direction towards the viewer `view`, all in the
    /// space the normals are in. [`Error::InvalidLighting`] for more than
    /// [`MAX_LIGHTS`] lights, a zero or non-finite direction, or a
    /// non-finite intensity.
    pub fn new(
        ambient: [f32; 3],
        lights: &[DirectionalLight],
        view: Vec3,
    ) -> Result<Lighting, Error> {
        let finite = |c: &[f32; 3]| c.iter().all(|v| v.is_finite());
        if lights.len() > MAX_LIGHTS || !finite(&ambient) {
            return Err(Error::InvalidLighting);
        }
        let v = normalize(view).ok_or(Error::InvalidLighting)?;
        let mut prepared = [Prepared::default(); MAX_LIGHTS];
        for (p, light) in prepared.iter_mut().zip(lights) {
            let l = normalize(light.direction).ok_or(Error::InvalidLighting)?;
            if !finite(&light.color) {
                return Err(Error::InvalidLighting);
            }
            // l = -v (light straight behind the viewer) has no half
            // vector; any unit vector will do, its highlight faces away.
            let h = normalize(l + v).unwrap_or(v);
            *p = Prepared {
                l,
                h,
                color: light.color,
            };
        }
        Ok(Lighting {
            ambient,
            lights: prepared,
            count: lights.len(),
        })
    }

    /// The lit colour (`0.0..=255.0`) of a surface of diffuse colour
    /// `base` (`0.0..=255.0`) and `material` with unit normal `n`:
    /// `base * (ambient + sum max(0, n.l) c) + 255 * Ks * sum max(0,
    /// n.h)^Ns c` over the lights (no highlight where `n.l <= 0`), each
    /// channel clamped to `0.0..=255.0` (a NaN from overflowing terms, such
    /// as a huge intensity times a black base, gives 0): always finite.
    #[inline]
    pub fn shade(&self, base: [f32; 3], material: &Material, n: Vec3) -> [f32; 3] {
        let mut diffuse = self.ambient;
        let mut spec = [0.0f32; 3];
        let specular = material.specular != [0.0; 3];
        for p in self.lights.iter().take(self.count) {
            let d = n.dot(p.l);
            if d > 0.0 {
                for (acc, c) in diffuse.iter_mut().zip(p.color) {
                    *acc += d * c;
                }
                if specular {
                    let s = n.dot(p.h);
                    if s > 0.0 {
                        let s = powi(s, material.shininess.min(1024) as u32);
                        for (acc, c) in spec.iter_mut().zip(p.color) {
                            *acc += s * c;
                        }
                    }
                }
            }
        }
        core::array::from_fn(|c| {
            channel(base[c] * diffuse[c] + 255.0 * material.specular[c] * spec[c])
        })
    }
}

/// Gouraud lighting: per-vertex colours from `base`, lit per vertex with
/// `normals` (one per vertex, unit length, indexed like positions) under
/// `lighting`; `N = 3` for [`VertexColor`]. A missing normal is a bad
/// index; a zero or non-finite one lights as ambient only.
#[derive(Clone, Copy, Debug)]
pub struct LitColors<'a> {
    /// The unlit (diffuse) colours.
    pub base: MeshColors<'a>,
    /// Unit normals, one per vertex.
    pub normals: &'a [Vec3],
    /// The lights.
    pub lighting: &'a Lighting,
    /// The surface.
    pub material: Material,
}

/// Triangle `idx` has an entry in `list` for each of its vertices.
#[inline]
fn all_in<T>(list: &[T], idx: [u32; 3]) -> bool {
    idx.iter().all(|&k| (k as usize) < list.len())
}

/// The normal of `vertex`, or zero (lit by ambient only) where missing or
/// non-finite.
#[inline]
fn normal_of(normals: &[Vec3], vertex: u32) -> Vec3 {
    match normals.get(vertex as usize) {
        Some(n) if n.is_finite() => *n,
        _ => Vec3::new(0.0, 0.0, 0.0),
    }
}

impl Attributes<3> for LitColors<'_> {
    const FINITE: bool = true;

    #[inline]
    fn complete(&self, triangles: usize, vertices: usize) -> bool {
        self.base.complete(triangles, vertices) && self.normals.len() >= vertices
    }
    #[inline]
    fn has(&self, tri: usize, idx: [u32; 3]) -> bool {
        self.base.has(tri, idx) && all_in(self.normals, idx)
    }
    #[inline]
    fn get(&self, tri: usize, vertex: u32) -> [f32; 3] {
        let base = self.base.get(tri, vertex);
        self.lighting
            .shade(base, &self.material, normal_of(self.normals, vertex))
    }
}

/// A colour source (`N = 3`, e.g. [`MeshColors`] or [`LitColors`]) and
/// texture coordinates per vertex: varyings `[r, g, b, u, v]` for
/// [`Textured`].
#[derive(Clone, Copy, Debug)]
pub struct ColorUv<'a, A> {
    /// The colour the texture is multiplied by (white for the texture as
    /// it is).
    pub color: A,
    /// `(u, v)` per vertex, indexed like positions.
    pub uvs: &'a [[f32; 2]],
}

impl<A: Attributes<3>> Attributes<5> for ColorUv<'_, A> {
    #[inline]
    fn complete(&self, triangles: usize, vertices: usize) -> bool {
        self.color.complete(triangles, vertices) && self.uvs.len() >= vertices
    }
    #[inline]
    fn has(&self, tri: usize, idx: [u32; 3]) -> bool {
        self.color.has(tri, idx) && all_in(self.uvs, idx)
    }
    #[inline]
    fn get(&self, tri: usize, vertex: u32) -> [f32; 5] {
        let c = self.color.get(tri, vertex);
        let uv = self.uvs.get(vertex as usize).copied().unwrap_or([0.0; 2]);
        [c[0], c[1], c[2], uv[0], uv[1]]
    }
}

/// Diffuse colours and normals per vertex, for lighting per pixel:
/// varyings `[r, g, b, nx, ny, nz]` for [`Phong`] without a texture.
#[derive(Clone, Copy, Debug)]
pub struct ColorNormal<'a> {
    /// The diffuse colours.
    pub color: MeshColors<'a>,
    /// Normals per vertex (need not be unit: they are normalised per
    /// pixel).
    pub normals: &'a [Vec3],
}

impl Attributes<6> for ColorNormal<'_> {
    const FINITE: bool = true;

    #[inline]
    fn complete(&self, triangles: usize, vertices: usize) -> bool {
        self.color.complete(triangles, vertices) && self.normals.len() >= vertices
    }
    #[inline]
    fn has(&self, tri: usize, idx: [u32; 3]) -> bool {
        self.color.has(tri, idx) && all_in(self.normals, idx)
    }
    #[inline]
    fn get(&self, tri: usize, vertex: u32) -> [f32; 6] {
        let c = self.color.get(tri, vertex);
        let n = normal_of(self.normals, vertex);
        [c[0], c[1], c[2], n.x, n.y, n.z]
    }
}

/// Colours, texture coordinates and normals per vertex: varyings `[r, g,
/// b, u, v, nx, ny, nz]` for a textured [`Phong`].
#[derive(Clone, Copy, Debug)]
pub struct ColorUvNormal<'a> {
    /// The colour the texture is multiplied by.
    pub color: MeshColors<'a>,
    /// `(u, v)` per vertex.
    pub uvs: &'a [[f32; 2]],
    /// Normals per vertex.
    pub normals: &'a [Vec3],
}

impl Attributes<8> for ColorUvNormal<'_> {
    #[inline]
    fn complete(&self, triangles: usize, vertices: usize) -> bool {
        self.color.complete(triangles, vertices)
            && self.uvs.len() >= vertices
            && self.normals.len() >= vertices
    }
    #[inline]
    fn has(&self, tri: usize, idx: [u32; 3]) -> bool {
        self.color.has(tri, idx) && all_in(self.uvs, idx) && all_in(self.normals, idx)
    }
    #[inline]
    fn get(&self, tri: usize, vertex: u32) -> [f32; 8] {
        let c = self.color.get(tri, vertex);
        let uv = self.uvs.get(vertex as usize).copied().unwrap_or([0.0; 2]);
        let n = normal_of(self.normals, vertex);
        [c[0], c[1], c[2], uv[0], uv[1], n.x, n.y, n.z]
    }
}

/// A texel type a [`Texture`] can hold.
pub trait Texel: Copy {
    /// Its colour, channels `0.0..=255.0`.
    fn rgb(self) -> [f32; 3];
}

impl Texel for Rgb888 {
    #[inline(always)]
    fn rgb(self) -> [f32; 3] {
        rgb_f32(self)
    }
}

impl Texel for Rgb565 {
    /// Widened as displays do: the top bits repeated into the low ones.
    #[inline(always)]
    fn rgb(self) -> [f32; 3] {
        let (r, g, b) = (self.r() as u32, self.g() as u32, self.b() as u32);
        [
            ((r << 3) | (r >> 2)) as f32,
            ((g << 2) | (g >> 4)) as f32,
            ((b << 3) | (b >> 2)) as f32,
        ]
    }
}

impl Texel for u16 {
    /// An `Rgb565` word (red in the top five bits), as displays and baked
    /// textures (`microraster bake`) store it; widened like [`Rgb565`].
    #[inline(always)]
    fn rgb(self) -> [f32; 3] {
        let (r, g, b) = (
            (self >> 11) as u32,
            ((self >> 5) & 63) as u32,
            (self & 31) as u32,
        );
        [
            ((r << 3) | (r >> 2)) as f32,
            ((g << 2) | (g >> 4)) as f32,
            ((b << 3) | (b >> 2)) as f32,
        ]
    }
}

/// How texture coordinates outside `0..1` are treated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    /// The texture tiles the plane.
    #[default]
    Repeat,
    /// The edge texels extend outwards.
    Clamp,
}

/// How a texel is chosen between texel centres.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Filter {
    /// The texel the point falls in.
    #[default]
    Nearest,
    /// The four nearest texels, weighted by distance.
    Bilinear,
}

/// The largest texture side: texel coordinates stay exact in `f32` and
/// products of sides fit `u32`.
pub const MAX_TEXTURE_SIDE: u32 = 1 << 14;

/// A texture in caller memory: `width * height` texels, row 0 first, any
/// size (powers of two wrap with a mask, others with a remainder).
#[derive(Clone, Copy, Debug)]
pub struct Texture<'a, T> {
    texels: &'a [T],
    width: u32,
    height: u32,
    wrap: Wrap,
    filter: Filter,
}

impl<'a, T: Texel> Texture<'a, T> {
    /// A `width x height` texture over `texels`, sampled nearest with
    /// repeat. [`Error::TextureSize`] unless `texels` holds exactly
    /// `width * height` texels and both sides are in
    /// `1..=`[`MAX_TEXTURE_SIDE`].
    pub fn new(texels: &'a [T], width: u32, height: u32) -> Result<Self, Error> {
        let ok_side = |s: u32| (1..=MAX_TEXTURE_SIDE).contains(&s);
        let expected = width as u64 * height as u64;
        if !ok_side(width) || !ok_side(height) || texels.len() as u64 != expected {
            return Err(Error::TextureSize {
                width,
                height,
                texels: texels.len(),
            });
        }
        Ok(Texture {
            texels,
            width,
            height,
            wrap: Wrap::Repeat,
            filter: Filter::Nearest,
        })
    }

    /// The same texture, sampled with `filter` and `wrap`.
    pub fn with_sampling(mut self, filter: Filter, wrap: Wrap) -> Self {
        self.filter = filter;
        self.wrap = wrap;
        self
    }

    /// Width and height in texels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Texel column or row `i` (any integer) wrapped into `0..n`.
    #[inline(always)]
    fn wrap_index(&self, i: i32, n: u32) -> usize {
        match self.wrap {
            Wrap::Clamp => i.clamp(0, n as i32 - 1) as usize,
            Wrap::Repeat if n.is_power_of_two() => (i as u32 & (n - 1)) as usize,
            Wrap::Repeat => i.rem_euclid(n as i32) as usize,
        }
    }

    #[inline(always)]
    fn texel(&self, x: i32, y: i32) -> [f32; 3] {
        let (x, y) = (
            self.wrap_index(x, self.width),
            self.wrap_index(y, self.height),
        );
        self.texels
            .get(y * self.width as usize + x)
            .map_or([0.0; 3], |t| t.rgb())
    }

    /// The colour (`0.0..=255.0`) at texture coordinates `(u, v)`; a
    /// non-finite coordinate samples texel `(0, 0)`'s neighbourhood.
    #[inline]
    pub fn sample(&self, u: f32, v: f32) -> [f32; 3] {
        // Texel space, kept within +-2^24 (exact in f32, wraps unchanged
        // for any side that divides 2^24, and saturates `as i32`).
        let lim = 16_777_216.0f32;
        let fin = |t: f32| {
            if t.is_finite() {
                t.clamp(-lim, lim)
            } else {
                0.0
            }
        };
        let x = fin(u * self.width as f32);
        let y = fin(v * self.height as f32);
        match self.filter {
            Filter::Nearest => self.texel(floor(x), floor(y)),
            Filter::Bilinear => {
                let (x, y) = (x - 0.5, y - 0.5);
                let (x0, y0) = (floor(x), floor(y));
                let (fx, fy) = (x - x0 as f32, y - y0 as f32);
                let a = self.texel(x0, y0);
                let b = self.texel(x0 + 1, y0);
                let c = self.texel(x0, y0 + 1);
                let d = self.texel(x0 + 1, y0 + 1);
                core::array::from_fn(|k| {
                    let top = a[k] + (b[k] - a[k]) * fx;
                    let bottom = c[k] + (d[k] - c[k]) * fx;
                    top + (bottom - top) * fy
                })
            }
        }
    }
}

/// `floor(x)` for `|x| <= 2^24` (no `std`).
#[inline(always)]
fn floor(x: f32) -> i32 {
    let i = x as i32;
    if (i as f32) > x {
        i - 1
    } else {
        i
    }
}

/// A texture multiplied by the interpolated colour: varyings `[r, g, b,
/// u, v]` (from [`ColorUv`]); white (255) shows the texture as it is, a
/// lit colour ([`LitColors`]) lights it per vertex.
#[derive(Clone, Copy, Debug)]
pub struct Textured<'a, T> {
    /// The texture.
    pub texture: Texture<'a, T>,
}

impl<T: Texel> FragmentShader<5> for Textured<'_, T> {
    #[inline]
    fn shade(&self, v: &[f32; 5], _: u32) -> Rgb888 {
        let t = self.texture.sample(v[3], v[4]);
        let m = |k: usize| to_u8(t[k] * v[k] * (1.0 / 255.0));
        Rgb888::new(m(0), m(1), m(2))
    }
}

/// No texture: the diffuse colour is the varyings' ([`Phong`]'s default).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NoTexture;

/// Lighting per pixel (Phong shading, Blinn-Phong highlight): the normal
/// is interpolated and normalised at every pixel. Without a texture the
/// varyings are `[r, g, b, nx, ny, nz]` ([`ColorNormal`]); with one,
/// `[r, g, b, u, v, nx, ny, nz]` ([`ColorUvNormal`]) and the diffuse
/// colour is the texture times the colour.
#[derive(Clone, Copy, Debug)]
pub struct Phong<'a, X = NoTexture> {
    /// The lights.
    pub lighting: &'a Lighting,
    /// The surface.
    pub material: Material,
    /// The texture, or [`NoTexture`].
    pub texture: X,
}

/// The unit normal from interpolated components (zero, lit by ambient
/// only, where it cannot be normalised).
#[inline(always)]
fn pixel_normal(x: f32, y: f32, z: f32) -> Vec3 {
    normalize(Vec3::new(x, y, z)).unwrap_or(Vec3::new(0.0, 0.0, 0.0))
}

/// A lit colour in `0.0..=255.0` to a pixel.
#[inline(always)]
fn rgb(c: [f32; 3]) -> Rgb888 {
    Rgb888::new(to_u8(c[0]), to_u8(c[1]), to_u8(c[2]))
}

impl FragmentShader<6> for Phong<'_, NoTexture> {
    #[inline]
    fn shade(&self, v: &[f32; 6], _: u32) -> Rgb888 {
        let n = pixel_normal(v[3], v[4], v[5]);
        rgb(self.lighting.shade([v[0], v[1], v[2]], &self.material, n))
    }
}

impl<T: Texel> FragmentShader<8> for Phong<'_, Texture<'_, T>> {
    #[inline]
    fn shade(&self, v: &[f32; 8], _: u32) -> Rgb888 {
        let t = self.texture.sample(v[3], v[4]);
        let base = core::array::from_fn(|k| t[k] * v[k] * (1.0 / 255.0));
        let n = pixel_normal(v[5], v[6], v[7]);
        rgb(self.lighting.shade(base, &self.material, n))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tex2x2() -> [Rgb888; 4] {
        [
            Rgb888::new(0, 0, 0),
            Rgb888::new(200, 0, 0),
            Rgb888::new(0, 200, 0),
            Rgb888::new(0, 0, 200),
        ]
    }

    #[test]
    fn texture_size_is_checked() {
        let t = tex2x2();
        assert!(Texture::new(&t, 2, 2).is_ok());
        for (w, h) in [(2, 1), (4, 2), (0, 4), (1, 0)] {
            assert_eq!(
                Texture::new(&t, w, h).err(),
                Some(Error::TextureSize {
                    width: w,
                    height: h,
                    texels: 4
                })
            );
        }
    }

    #[test]
    fn nearest_repeat_and_clamp() {
        let t = tex2x2();
        let tex = Texture::new(&t, 2, 2).unwrap();
        assert_eq!(tex.sample(0.75, 0.25), [200.0, 0.0, 0.0]);
        assert_eq!(tex.sample(1.75, -0.75), [200.0, 0.0, 0.0]);
        assert_eq!(tex.sample(f32::NAN, 0.1), [0.0, 0.0, 0.0]);
        let c = tex.with_sampling(Filter::Nearest, Wrap::Clamp);
        assert_eq!(c.sample(5.0, 5.0), [0.0, 0.0, 200.0]);
        assert_eq!(c.sample(-5.0, -5.0), [0.0, 0.0, 0.0]);
    }

    #[test]
    fn bilinear_at_centre_averages_four() {
        let t = tex2x2();
        let tex = Texture::new(&t, 2, 2)
            .unwrap()
            .with_sampling(Filter::Bilinear, Wrap::Clamp);
        assert_eq!(tex.sample(0.5, 0.5), [50.0, 50.0, 50.0]);
        // At a texel centre: that texel.
        assert_eq!(tex.sample(0.75, 0.25), [200.0, 0.0, 0.0]);
    }

    #[test]
    fn rgb565_words_sample_like_rgb565() {
        for c in [
            Rgb565::new(31, 0, 0),
            Rgb565::new(0, 63, 0),
            Rgb565::new(3, 40, 17),
        ] {
            use embedded_graphics_core::pixelcolor::raw::ToBytes;
            let word = u16::from_be_bytes(c.to_be_bytes());
            assert_eq!(word.rgb(), c.rgb());
        }
    }

    #[test]
    fn non_power_of_two_wraps() {
        let t = [
            Rgb565::new(31, 0, 0),
            Rgb565::new(0, 63, 0),
            Rgb565::new(0, 0, 31),
        ];
        let tex = Texture::new(&t, 3, 1).unwrap();
        assert_eq!(tex.sample(-0.1, 0.0), [0.0, 0.0, 255.0]);
        assert_eq!(tex.sample(1.5, 0.0), [0.0, 255.0, 0.0]);
    }

    #[test]
    fn lighting_is_checked_and_lambert() {
        let sun = DirectionalLight {
            direction: Vec3::new(0.0, 0.0, 2.0),
            color: [1.0; 3],
        };
        let l = Lighting::new([0.1; 3], &[sun], Vec3::new(0.0, 0.0, 1.0)).unwrap();
        let c = l.shade([200.0; 3], &Material::MATTE, Vec3::new(0.0, 0.6, 0.8));
        for ch in c {
            assert!((ch - 200.0 * (0.1 + 0.8)).abs() < 1e-3);
        }
        // Facing away: ambient only.
        let c = l.shade([200.0; 3], &Material::MATTE, Vec3::new(0.0, 0.0, -1.0));
        assert!((c[0] - 20.0).abs() < 1e-4);
        let bad = DirectionalLight {
            direction: Vec3::new(0.0, 0.0, 0.0),
            color: [1.0; 3],
        };
        assert_eq!(
            Lighting::new([0.1; 3], &[bad], Vec3::new(0.0, 0.0, 1.0)),
            Err(Error::InvalidLighting)
        );
        assert_eq!(
            Lighting::new([0.1; 3], &[sun; 5], Vec3::new(0.0, 0.0, 1.0)),
            Err(Error::InvalidLighting)
        );
    }

    #[test]
    fn any_finite_nonzero_direction_is_a_light() {
        for d in [
            Vec3::new(-1e-45, 0.0, 0.0),
            Vec3::new(1e-30, 0.0, 0.0),
            Vec3::new(1e20, 0.0, 0.0),
            Vec3::new(-3.9e29, -0.5, 72.7),
            Vec3::new(f32::MAX, f32::MAX, -f32::MAX),
        ] {
            let sun = DirectionalLight {
                direction: d,
                color: [1.0; 3],
            };
            let l = Lighting::new([0.1; 3], &[sun], d).unwrap();
            let n = l.lights[0].l;
            assert!((n.dot(n) - 1.0).abs() < 1e-5, "{d:?}: {n:?}");
        }
        // Found by fuzzing (fuzz/findings/lighting-nan-*): a NaN next to a
        // finite component is refused, in a light and in the view.
        for d in [
            Vec3::new(1.0, f32::NAN, 0.0),
            Vec3::new(-30000.0, -385.85938, f32::NAN),
            Vec3::new(-2.95e20, -1e5, f32::NAN),
            Vec3::new(f32::INFINITY, 0.0, 1.0),
        ] {
            let sun = DirectionalLight {
                direction: d,
                color: [1.0; 3],
            };
            let up = Vec3::new(0.0, 0.0, 1.0);
            assert_eq!(Lighting::new([0.1; 3], &[], d), Err(Error::InvalidLighting));
            assert_eq!(
                Lighting::new([0.1; 3], &[sun], up),
                Err(Error::InvalidLighting)
            );
        }
    }

    #[test]
    fn lit_colours_are_always_finite() {
        let sun = DirectionalLight {
            direction: Vec3::new(0.0, 0.0, 1.0),
            color: [f32::MAX; 3],
        };
        let l = Lighting::new([f32::MAX; 3], &[sun; 4], Vec3::new(0.0, 0.0, 1.0)).unwrap();
        let shiny = Material {
            specular: [0.0, 1.0, 0.5],
            shininess: 1,
        };
        for base in [[0.0; 3], [255.0; 3], [1.0, 0.0, 7.0]] {
            for n in [
                Vec3::new(0.0, 0.0, 1.0),
                Vec3::new(0.0, 0.0, -1.0),
                Vec3::new(0.0, 0.0, 0.0),
            ] {
                let c = l.shade(base, &shiny, n);
                assert!(
                    c.iter().all(|v| (0.0..=255.0).contains(v)),
                    "{base:?} {n:?}: {c:?}"
                );
            }
        }
    }

    #[test]
    fn highlight_peaks_at_the_half_vector() {
        let sun = DirectionalLight {
            direction: Vec3::new(0.0, 0.0, 1.0),
            color: [1.0; 3],
        };
        let l = Lighting::new([0.0; 3], &[sun], Vec3::new(0.0, 0.0, 1.0)).unwrap();
        let shiny = Material {
            specular: [0.5; 3],
            shininess: 32,
        };
        let c = l.shade([100.0; 3], &shiny, Vec3::new(0.0, 0.0, 1.0));
        assert!((c[0] - (100.0 + 127.5)).abs() < 1e-3);
        // Exact (powers of two and small integers), so also under Miri,
        // whose `f32::powi` is not.
        assert_eq!(powi(0.5, 10), 1.0 / 1024.0);
        assert_eq!(powi(3.0, 5), 243.0);
        assert_eq!(powi(0.7, 0), 1.0);
    }
}
