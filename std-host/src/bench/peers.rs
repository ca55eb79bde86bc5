//! Other renderers drawing the same scenes, for `microraster bench --peers`.
//!
//! Design: each peer gets the scene's own data, converted once outside any
//! timed region, and draws it with settings as close to microraster's as
//! the peer allows:
//!
//! - [`euc`] (crates.io, 0.5): the same triangles and matrices, per-vertex
//!   colours interpolated perspective-correctly (Gouraud; flat scenes give
//!   their triangles three equal colours), back faces culled with the same
//!   winding (counter-clockwise in NDC is front), depth test "less" and
//!   depth writes. euc's depth buffer is `f32` (it has no integer depth) and
//!   it has no clipping, so scenes must lie in front of the eye (all
//!   built-in scenes do). Its colour buffer holds the same pixel format
//!   packed into an integer (`u16` RGB565 or `u32` RGB888).
//! - embedded-graphics' filled [`Triangle`] primitive: the scene's visible
//!   triangles projected to integer pixel positions ([`project_2d`]) and drawn
//!   flat into [`Framebuffer`], a plain `Vec<Rgb565>` `DrawTarget`.
//!   microraster draws the same integer triangles (vertices at the pixel
//!   centres, as clip-space triangles: [`tris_2d_scene`]) without depth
//!   into RGB565.
//!
//! [`peers_section`] times them against microraster on one thread. The
//! module is compiled only with the `peers` feature, so the default build
//! links neither peer.

use super::runs::{BenchColor, Run};
use super::stats::{ms, time_frames, Summary};
use super::Settings;
use crate::bench_scenes::BenchScene;
use crate::cliptris::ClipTri;
use crate::pipeline::FramePipeline;
use crate::scene::{Object, ObjectColors, Scene};
use embedded_graphics::pixelcolor::{Rgb565, Rgb888, RgbColor};
use embedded_graphics::prelude::{
    DrawTarget, OriginDimensions, Point, PointsIter, Primitive, Size,
};
use embedded_graphics::primitives::{PrimitiveStyle, Rectangle, Triangle};
use embedded_graphics::Drawable;
use euc::buffer::Buffer2d;
use euc::rasterizer::{BackfaceCullingDisabled, BackfaceCullingEnabled, Triangles};
use euc::{Pipeline, Target};
use microraster::Config;
use microraster::{CullMode, Mat4, Vec3, Vec4};
use serde_json::{json, Value};
use std::convert::Infallible;
use std::time::Instant;

/// The euc version benchmarked (as in `std-host/Cargo.toml`).
pub const EUC_VERSION: &str = "0.5";

/// An integer packing of an 8-bit-per-channel colour, as euc's pixel.
pub trait PackedPixel: Copy + PartialEq + Send + 'static {
    /// The colour `r, g, b` in `0.0..=255.0`.
    fn pack(r: f32, g: f32, b: f32) -> Self;
}

impl PackedPixel for u16 {
    /// RGB565, keeping the top bits of each channel (as embedded-graphics'
    /// `Rgb565::from(Rgb888)`).
    #[inline(always)]
    fn pack(r: f32, g: f32, b: f32) -> Self {
        let (r, g, b) = (r as u8 as u16, g as u8 as u16, b as u8 as u16);
        ((r >> 3) << 11) | ((g >> 2) << 5) | (b >> 3)
    }
}

impl PackedPixel for u32 {
    /// `0x00RRGGBB`.
    #[inline(always)]
    fn pack(r: f32, g: f32, b: f32) -> Self {
        let (r, g, b) = (r as u8 as u32, g as u8 as u32, b as u8 as u32);
        (r << 16) | (g << 8) | b
    }
}

/// One object as an euc pipeline: vertex = (vertex index, triangle index).
struct EucObject<'a, P> {
    mvp: Mat4,
    positions: &'a [Vec3],
    colors: &'a ObjectColors,
    _pixel: std::marker::PhantomData<P>,
}

impl<P: PackedPixel> Pipeline for EucObject<'_, P> {
    type Vertex = [u32; 2];
    type VsOut = (f32, f32, f32);
    type Pixel = P;

    #[inline(always)]
    fn vert(&self, v: &Self::Vertex) -> ([f32; 4], Self::VsOut) {
        // Indices were checked when the vertex list was built.
        let p = self.mvp.transform_point(self.positions[v[0] as usize]);
        let c = match self.colors {
            ObjectColors::PerVertex(c) => c[v[0] as usize],
            ObjectColors::PerTriangle(c) => c[v[1] as usize],
        };
        (
            [p.x, p.y, p.z, p.w],
            (c.r() as f32, c.g() as f32, c.b() as f32),
        )
    }

    #[inline(always)]
    fn frag(&self, c: &Self::VsOut) -> Self::Pixel {
        P::pack(c.0, c.1, c.2)
    }
}

/// euc's inputs and buffers for a scene, built once.
pub struct EucScene<P> {
    /// Per object: its vertex list (three entries per triangle).
    vertices: Vec<Vec<[u32; 2]>>,
    /// Colour target.
    pub color: Buffer2d<P>,
    /// Depth target (`f32`, cleared to 1.0 = far).
    pub depth: Buffer2d<f32>,
    clear: P,
    cull: bool,
}

impl<P: PackedPixel> EucScene<P> {
    /// Prepares `scene` (its objects; raw clip-space triangles are not
    /// drawn) for euc at `width x height`. Triangles with an index or colour
    /// out of range are left out. Culling other than back or none is
    /// refused: euc only culls back faces.
    pub fn new(scene: &Scene, width: u32, height: u32, cull: CullMode) -> Result<Self, String> {
        let cull = match cull {
            CullMode::Back => true,
            CullMode::None => false,
            CullMode::Front => return Err("euc cannot cull front faces".into()),
        };
        let vertices = scene.objects.iter().map(euc_vertices).collect();
        let size = [width as usize, height as usize];
        let clear = P::pack(0.0, 0.0, 0.0);
        Ok(EucScene {
            vertices,
            color: Buffer2d::new(size, clear),
            depth: Buffer2d::new(size, 1.0),
            clear,
            cull,
        })
    }

    /// Clears both buffers and draws every object with its current matrix.
    pub fn draw(&mut self, scene: &Scene) {
        self.color.clear(self.clear);
        self.depth.clear(1.0);
        for (o, verts) in scene.objects.iter().zip(&self.vertices) {
            let pipe = EucObject::<P> {
                mvp: o.mvp,
                positions: &o.positions,
                colors: &o.colors,
                _pixel: std::marker::PhantomData,
            };
            if self.cull {
                pipe.draw::<Triangles<'_, Buffer2d<f32>, BackfaceCullingEnabled>, _>(
                    verts,
                    &mut self.color,
                    Some(&mut self.depth),
                );
            } else {
                pipe.draw::<Triangles<'_, Buffer2d<f32>, BackfaceCullingDisabled>, _>(
                    verts,
                    &mut self.color,
                    Some(&mut self.depth),
                );
            }
        }
    }

    /// Pixels that differ from the background.
    pub fn covered(&self) -> u64 {
        self.color
            .as_ref()
            .iter()
            .filter(|&&p| p != self.clear)
            .count() as u64
    }
}

fn euc_vertices(o: &Object) -> Vec<[u32; 2]> {
    let n = o.positions.len();
    let mut out = Vec::with_capacity(o.indices.len() * 3);
    for (i, t) in o.indices.iter().enumerate() {
        let ok = t.iter().all(|&v| (v as usize) < n)
            && match &o.colors {
                ObjectColors::PerVertex(c) => t.iter().all(|&v| (v as usize) < c.len()),
                ObjectColors::PerTriangle(c) => i < c.len(),
            };
        if ok {
            out.extend(t.iter().map(|&v| [v, i as u32]));
        }
    }
    out
}

/// A triangle in window pixels (`Point`s: pixel `(x, y)` has its centre at
/// `(x + 0.5, y + 0.5)`), flat colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tri2d {
    /// The corners.
    pub p: [Point; 3],
    /// The fill colour.
    pub color: Rgb565,
}

/// The triangles of `scene`'s objects that microraster would draw at
/// `width x height` with culling `cull`, in window pixels: each corner
/// rounded to the nearest pixel centre. Left out: triangles with a vertex
/// behind the eye (`w <= 0`), not finite, or out of index range; triangles
/// entirely outside one side of the frustum; culled faces; and triangles
/// whose rounded corners are collinear. Colour: the triangle's, or its first
/// vertex's for per-vertex colours.
pub fn project_2d(scene: &Scene, width: u32, height: u32, cull: CullMode) -> Vec<Tri2d> {
    let (w, h) = (width as f32, height as f32);
    let mut out = Vec::new();
    for o in &scene.objects {
        let mesh = o.mesh();
        for i in 0..o.indices.len() {
            let Some(v) = mesh.triangle(i, &o.mvp) else {
                continue;
            };
            let clip = v.map(|v| v.pos);
            if !clip.iter().all(|p| p.is_finite() && p.w > 0.0) {
                continue;
            }
            let outside = |f: fn(&Vec4) -> bool| clip.iter().all(f);
            if outside(|p| p.x < -p.w)
                || outside(|p| p.x > p.w)
                || outside(|p| p.y < -p.w)
                || outside(|p| p.y > p.w)
                || outside(|p| p.z < -p.w)
                || outside(|p| p.z > p.w)
            {
                continue;
            }
            let ndc = clip.map(|p| (p.x / p.w, p.y / p.w));
            let area = (ndc[1].0 - ndc[0].0) * (ndc[2].1 - ndc[0].1)
                - (ndc[2].0 - ndc[0].0) * (ndc[1].1 - ndc[0].1);
            let keep = match cull {
                CullMode::Back => area > 0.0,
                CullMode::Front => area < 0.0,
                CullMode::None => area != 0.0,
            };
            if !keep {
                continue;
            }
            let px = ndc.map(|(x, y)| {
                let wx = (x + 1.0) * w * 0.5;
                let wy = (1.0 - y) * h * 0.5;
                let r = |v: f32| (v - 0.5).round().clamp(-1e6, 1e6) as i32;
                Point::new(r(wx), r(wy))
            });
            let iarea = (px[1].x - px[0].x) as i64 * (px[2].y - px[0].y) as i64
                - (px[2].x - px[0].x) as i64 * (px[1].y - px[0].y) as i64;
            if iarea == 0 {
                continue;
            }
            let c = v[0].varyings;
            let color = Rgb565::from(Rgb888::new(c[0] as u8, c[1] as u8, c[2] as u8));
            out.push(Tri2d { p: px, color });
        }
    }
    out
}

/// `tris` as a scene of clip-space triangles whose window corners are the
/// pixel centres of the 2D corners (`z = 0`, `w = 1`), in a
/// `width x height` frame.
pub fn tris_2d_scene(tris: &[Tri2d], width: u32, height: u32) -> Scene {
    let (w, h) = (width as f32, height as f32);
    let clip_tris = tris
        .iter()
        .map(|t| {
            let c = Rgb888::from(t.color);
            ClipTri {
                v: t.p.map(|p| {
                    [
                        (p.x as f32 + 0.5) * 2.0 / w - 1.0,
                        1.0 - (p.y as f32 + 0.5) * 2.0 / h,
                        0.0,
                        1.0,
                    ]
                }),
                color: Some([c.r(), c.g(), c.b()]),
            }
        })
        .collect();
    crate::scene::clip_tris_scene(clip_tris)
}

/// Draws `tris` with embedded-graphics' filled `Triangle`.
pub fn draw_eg<D: DrawTarget<Color = Rgb565>>(
    target: &mut D,
    tris: &[Tri2d],
) -> Result<(), D::Error> {
    for t in tris {
        Triangle::new(t.p[0], t.p[1], t.p[2])
            .into_styled(PrimitiveStyle::with_fill(t.color))
            .draw(target)?;
    }
    Ok(())
}

/// A whole-frame RGB565 framebuffer for embedded-graphics, row 0 first.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Framebuffer {
    width: u32,
    height: u32,
    /// The pixels, `width * height`, row 0 (top) first.
    pub pixels: Vec<Rgb565>,
}

impl Framebuffer {
    /// A `width x height` framebuffer filled with black.
    pub fn new(width: u32, height: u32) -> Self {
        Framebuffer {
            width,
            height,
            pixels: vec![Rgb565::BLACK; width as usize * height as usize],
        }
    }

    /// Pixels that are not black.
    pub fn covered(&self) -> u64 {
        self.pixels.iter().filter(|&&p| p != Rgb565::BLACK).count() as u64
    }

    /// The row range `x0..x1` of row `y`, clipped; `None` if empty.
    fn span(&self, area: &Rectangle) -> Option<(usize, usize, usize, usize)> {
        let a = area.intersection(&Rectangle::new(Point::zero(), self.size()));
        let br = a.bottom_right()?;
        Some((
            a.top_left.x as usize,
            br.x as usize + 1,
            a.top_left.y as usize,
            br.y as usize + 1,
        ))
    }
}

impl OriginDimensions for Framebuffer {
    fn size(&self) -> Size {
        Size::new(self.width, self.height)
    }
}

impl DrawTarget for Framebuffer {
    type Color = Rgb565;
    type Error = Infallible;

    fn draw_iter<I>(&mut self, pixels: I) -> Result<(), Self::Error>
    where
        I: IntoIterator<Item = embedded_graphics::Pixel<Self::Color>>,
    {
        let (w, h) = (self.width as i32, self.height as i32);
        for embedded_graphics::Pixel(p, c) in pixels {
            if p.x >= 0 && p.y >= 0 && p.x < w && p.y < h {
                self.pixels[p.y as usize * w as usize + p.x as usize] = c;
            }
        }
        Ok(())
    }

    fn fill_contiguous<I>(&mut self, area: &Rectangle, colors: I) -> Result<(), Self::Error>
    where
        I: IntoIterator<Item = Self::Color>,
    {
        let (w, h) = (self.width as i32, self.height as i32);
        for (p, c) in area.points().zip(colors) {
            if p.x >= 0 && p.y >= 0 && p.x < w && p.y < h {
                self.pixels[p.y as usize * w as usize + p.x as usize] = c;
            }
        }
        Ok(())
    }

    fn fill_solid(&mut self, area: &Rectangle, color: Self::Color) -> Result<(), Self::Error> {
        if let Some((x0, x1, y0, y1)) = self.span(area) {
            let w = self.width as usize;
            for y in y0..y1 {
                self.pixels[y * w + x0..y * w + x1].fill(color);
            }
        }
        Ok(())
    }

    fn clear(&mut self, color: Self::Color) -> Result<(), Self::Error> {
        self.pixels.fill(color);
        Ok(())
    }
}

/// euc and embedded-graphics against microraster, one thread.
pub fn peers_section<const S: u32, C: BenchColor>(
    bs: &mut BenchScene,
    s: &Settings,
    mr: &Run,
) -> Result<Value, String> {
    let mr_sum = Summary::of(&mr.total);
    let mut mr_json = mr_sum.json();
    mr_json["covered_pixels"] = json!(mr.covered);
    let mut o = json!({ "threads": 1, "microraster": mr_json });

    // euc: same scene, same frames.
    if bs.scene.objects.is_empty() {
        o["euc"] = json!("skipped: the scene has no meshes");
    } else if s.cull == CullMode::Front {
        o["euc"] = json!("skipped: euc cannot cull front faces");
    } else {
        let mut e = EucScene::<C::Packed>::new(&bs.scene, s.width, s.height, s.cull)?;
        let mut times = Vec::new();
        for k in 0..s.warmup + s.frames {
            bs.set_frame(k);
            let t = Instant::now();
            e.draw(&bs.scene);
            if k >= s.warmup {
                times.push(ms(t));
            }
        }
        let sum = Summary::of(&times);
        let mut ej = sum.json();
        ej["version"] = json!(EUC_VERSION);
        ej["depth"] = json!("f32");
        ej["covered_pixels"] = json!(e.covered());
        o["euc"] = ej;
        o["euc_over_microraster"] = json!(sum.median / mr_sum.median);
        o["euc_over_microraster_min"] = json!(sum.min / mr_sum.min);
    }

    // embedded-graphics: the same 2D triangles, flat, no depth, RGB565.
    bs.set_frame(0);
    let tris = project_2d(&bs.scene, s.width, s.height, s.cull);
    let mut fb = Framebuffer::new(s.width, s.height);
    let eg = time_frames(s.warmup, s.frames, |_| {
        use embedded_graphics::prelude::DrawTarget;
        let _ = fb.clear(Rgb565::BLACK);
        let _ = draw_eg(&mut fb, &tris);
        Ok(())
    })?;
    let flat = tris_2d_scene(&tris, s.width, s.height);
    let mut config = Config::new(s.width, s.height);
    config.cull = CullMode::None;
    let len = s.width as usize * s.height as usize;
    let mut color = vec![Rgb565::BLACK; len];
    let mut pipe = FramePipeline::<S>::new(config, 1, s.strip_rows);
    let ours = time_frames(s.warmup, s.frames, |_| {
        pipe.render::<Rgb565, u32>(&flat, &mut color, None, Rgb565::BLACK)?;
        Ok(())
    })?;
    let (eg_sum, ours_sum) = (Summary::of(&eg), Summary::of(&ours));
    let mut gm = ours_sum.json();
    gm["covered_pixels"] = json!(color.iter().filter(|&&c| c != Rgb565::BLACK).count());
    let mut ge = eg_sum.json();
    ge["covered_pixels"] = json!(fb.covered());
    o["embedded_graphics_2d"] = json!({
        "triangles": tris.len(),
        "microraster": gm,
        "embedded_graphics": ge,
        "eg_over_microraster": eg_sum.median / ours_sum.median,
        "method": "the scene's visible triangles (frame 0) projected and rounded to pixel \
             centres outside the clock; flat colour, RGB565, no depth, no culling; both clear \
             a whole-frame buffer and draw every triangle each frame (microraster: setup, \
             binning and drawing of the same triangles as clip-space input).",
    });
    Ok(o)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench_scenes::sphere_scene;
    use crate::render::{DepthKind, RenderOptions};
    use crate::scene::View;

    fn opts(width: u32, height: u32, depth: DepthKind) -> RenderOptions {
        RenderOptions {
            width,
            height,
            cull: CullMode::Back,
            detail: 0,
            depth,
            subpixel: 8,
            threads: 1,
            strip_rows: 16,
            tile_width: 0,
            ids: false,
            mode: microraster::RasterMode::Clipping,
            inv_w: false,
            occlusion: crate::render::Occlusion::Off,
        }
    }

    #[test]
    fn euc_draws_the_sphere_like_microraster() {
        let (scene, _) = sphere_scene(&View::new(120, 160), 24, 24).unwrap();
        let mut e = EucScene::<u16>::new(&scene, 120, 160, CullMode::Back).unwrap();
        e.draw(&scene);
        let mr = crate::render::render(&scene, &opts(120, 160, DepthKind::U16)).unwrap();
        let ours = mr.rgb.chunks(3).filter(|p| p != &[0, 0, 0]).count() as f64;
        let theirs = e.covered() as f64;
        assert!(ours > 1000.0);
        assert!((ours - theirs).abs() < 0.03 * ours, "{ours} vs {theirs}");
        assert!(EucScene::<u32>::new(&scene, 8, 8, CullMode::Front).is_err());
    }

    #[test]
    fn framebuffer_clips_and_fills() {
        let mut fb = Framebuffer::new(8, 4);
        fb.fill_solid(
            &Rectangle::new(Point::new(-2, 1), Size::new(4, 10)),
            Rgb565::RED,
        )
        .unwrap();
        assert_eq!(fb.covered(), 2 * 3);
        fb.fill_contiguous(
            &Rectangle::new(Point::new(7, 3), Size::new(2, 2)),
            [Rgb565::GREEN; 4],
        )
        .unwrap();
        assert_eq!(fb.pixels[3 * 8 + 7], Rgb565::GREEN);
        fb.draw_iter([embedded_graphics::Pixel(Point::new(-1, 0), Rgb565::BLUE)])
            .unwrap();
        assert_eq!(fb.covered(), 7);
        fb.clear(Rgb565::BLACK).unwrap();
        assert_eq!(fb.covered(), 0);
    }

    #[test]
    fn same_2d_triangles_cover_about_the_same_pixels() {
        let (scene, _) = sphere_scene(&View::new(120, 160), 16, 16).unwrap();
        let tris = project_2d(&scene, 120, 160, CullMode::Back);
        // More than half the faces point away (or leave the frame).
        assert!(tris.len() > 100 && tris.len() < 256, "{}", tris.len());
        let mut fb = Framebuffer::new(120, 160);
        draw_eg(&mut fb, &tris).unwrap();
        let flat = tris_2d_scene(&tris, 120, 160);
        let mut o = opts(120, 160, DepthKind::None);
        o.cull = CullMode::None;
        let r = crate::render::render(&flat, &o).unwrap();
        assert_eq!(r.stats.stored as usize, tris.len());
        let ours = r.rgb.chunks(3).filter(|p| p != &[0, 0, 0]).count() as f64;
        let theirs = fb.covered() as f64;
        // embedded-graphics also draws the pixels its edges touch.
        assert!(ours > 0.9 * theirs && ours <= theirs, "{ours} vs {theirs}");
    }
}
