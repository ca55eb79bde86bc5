//! The `StripDrawer` arm: a frame pushed through a strip buffer into a
//! recording `DrawTarget`, in immediate mode (`draw` / `draw_subpixel`,
//! the scene submitted to a `StripRenderer` per strip) or from the frame
//! (`draw_frame`), against `Frame::render_rows` of the same strips.
//!
//! Checked: render errors (colour strip under one row, depth strip too
//! short, bad frame size) come first and push nothing and call no scene;
//! otherwise one `fill_contiguous` per strip, top to bottom, each over
//! exactly its rows (`origin.y` saturating-plus `y0`, the frame's width),
//! with exactly the pixels of `render_rows` for those rows (buffers
//! cleared to the background and the clear depth) converted with `From`;
//! `draw_iter` is never used; a target error stops the frame at once and
//! is handed back; `pixels_written` is the sum over the strips pushed.

use crate::{submit_strip, DepthGuard, DrawerIn, PixelWord, Prep, Way, PIXEL_BUDGET};
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Point, Size};
use embedded_graphics_core::pixelcolor::{BinaryColor, Gray8, PixelColor, Rgb565, Rgb888};
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
use microraster::{Config, DrawError, Error, Frame, NoDepth, StripDrawer};

/// A target that records every `fill_contiguous` and can fail on one.
struct Rec<C> {
    size: Size,
    calls: Vec<(Rectangle, Vec<C>)>,
    fail_at: Option<usize>,
    iter_used: bool,
}

impl<C: PixelColor> OriginDimensions for Rec<C> {
    fn size(&self) -> Size {
        self.size
    }
}

impl<C: PixelColor> DrawTarget for Rec<C> {
    type Color = C;
    type Error = usize;
    fn draw_iter<I: IntoIterator<Item = Pixel<C>>>(&mut self, _: I) -> Result<(), usize> {
        self.iter_used = true;
        Ok(())
    }
    fn fill_contiguous<I: IntoIterator<Item = C>>(
        &mut self,
        area: &Rectangle,
        colors: I,
    ) -> Result<(), usize> {
        let n = area.size.width as usize * area.size.height as usize;
        let v: Vec<C> = colors.into_iter().take(n + 1).collect();
        let k = self.calls.len();
        self.calls.push((*area, v));
        if self.fail_at == Some(k) {
            Err(k)
        } else {
            Ok(())
        }
    }
}

fn coord((k, v): (u8, i16)) -> i32 {
    let a = v.unsigned_abs() as i32;
    match k % 3 {
        0 => i32::MIN + a,
        1 => i32::MAX - a,
        _ => v as i32,
    }
}

/// Runs the arm on a built frame (the scene: `preps`).
pub(crate) fn run<const S: u32>(
    d: &DrawerIn,
    depth_kind: u8,
    frame: &Frame<'_, S>,
    preps: &[Prep],
) {
    macro_rules! fmt {
        ($w:ty, $dep:expr) => {
            match d.format % 7 {
                0 => arm::<S, Rgb565, Rgb565, $w>(d, frame, preps, $dep, Rgb565::new(3, 9, 27)),
                1 => arm::<S, Gray8, Gray8, $w>(d, frame, preps, $dep, Gray8::new(d.background[0])),
                2 => arm::<S, BinaryColor, BinaryColor, $w>(
                    d,
                    frame,
                    preps,
                    $dep,
                    BinaryColor::from(d.background[0] & 1 == 1),
                ),
                3 => arm::<S, Rgb888, Rgb565, $w>(d, frame, preps, $dep, bg888(d)),
                4 => arm::<S, Rgb888, Rgb888, $w>(d, frame, preps, $dep, bg888(d)),
                5 => arm::<S, Rgb888, Gray8, $w>(d, frame, preps, $dep, bg888(d)),
                _ => arm::<S, Rgb888, BinaryColor, $w>(d, frame, preps, $dep, bg888(d)),
            }
        };
    }
    match depth_kind % 3 {
        0 => fmt!(u16, true),
        1 => fmt!(u32, true),
        _ => fmt!(u32, false),
    }
}

fn bg888(d: &DrawerIn) -> Rgb888 {
    Rgb888::new(d.background[0], d.background[1], d.background[2])
}

/// A frame of invalid size is refused before anything is drawn.
pub(crate) fn invalid_size<const S: u32>(d: &DrawerIn, config: Config) {
    let mut color = vec![Rgb565::new(0, 0, 0); 1 + d.rows as usize % 64];
    let mut drawer = StripDrawer::new(&mut color[..], NoDepth, Rgb565::new(0, 0, 0));
    let mut t = Rec::<Rgb565> {
        size: Size::new(4, 4),
        calls: Vec::new(),
        fail_at: None,
        iter_used: false,
    };
    let mut called = 0;
    let r = drawer.draw_subpixel::<_, _, S>(&mut t, config, |_| called += 1);
    assert_eq!(
        r,
        Err(DrawError::Render(Error::InvalidFrameSize {
            width: config.width,
            height: config.height
        }))
    );
    assert_eq!((t.calls.len(), called), (0, 0), "an error drew");
}

/// What the drawer should push: per strip, its pixels and pixels written.
fn expected<const S: u32, P: PixelWord, W: DepthGuard>(
    frame: &Frame<'_, S>,
    rows: u32,
    strips: usize,
    bg: P,
    clear_z32: u32,
    use_depth: bool,
) -> Vec<(u32, u32, Vec<P>, u64)> {
    let (w, h) = (frame.config().width as usize, frame.config().height);
    let mut out = Vec::new();
    let mut y0 = 0;
    while y0 < h && out.len() < strips {
        let y1 = y0.saturating_add(rows).min(h);
        let len = w * (y1 - y0) as usize;
        let mut c = vec![bg; len];
        let mut z = vec![W::from_z32(clear_z32); len];
        let r = if use_depth {
            frame.render_rows(y0, y1, &mut c, &mut z[..])
        } else {
            frame.render_rows(y0, y1, &mut c, &mut NoDepth)
        };
        out.push((y0, y1, c, r.expect("render_rows").pixels_written));
        y0 = y1;
    }
    out
}

fn arm<const S: u32, P, T, W>(
    d: &DrawerIn,
    frame: &Frame<'_, S>,
    preps: &[Prep],
    use_depth: bool,
    bg: P,
) where
    P: PixelWord,
    T: PixelColor + From<P> + PartialEq + core::fmt::Debug,
    W: DepthGuard,
{
    let config = *frame.config();
    let (w, h) = (config.width as usize, config.height);
    let buf_rows = d.rows as usize % (PIXEL_BUDGET / w + 1);
    let len = w * buf_rows + d.extra as usize % (w + 1);
    // Sentinels: a refused frame must leave both strips as they were.
    let mut color = vec![P::GUARD; len];
    let dlen = (len as i64 + d.depth_delta as i64).max(0) as usize;
    let mut depth = vec![W::GUARD; dlen];
    let origin = Point::new(coord(d.origin[0]), coord(d.origin[1]));
    let clear_z32 = match d.clear_kind % 3 {
        0 => u32::MAX,
        1 => 0,
        _ => d.clear_z32,
    };
    let rows = (len / w).min(h as usize) as u32;
    // Depth words round-trip as documented.
    let z = W::from_z32(clear_z32).to_z32();
    assert_eq!(
        z,
        if W::WIDE {
            clear_z32
        } else {
            clear_z32 & 0xffff_0000
        }
    );
    assert_eq!((W::NEAR.to_z32(), W::FAR.to_z32() | 0xffff), (0, u32::MAX));
    // Whole frames within the budget; beyond it, the target fails on the
    // first strip.
    let fits = w * h as usize <= PIXEL_BUDGET;
    let strips_total = if rows == 0 {
        0
    } else {
        h.div_ceil(rows) as usize
    };
    let fail_at = match d.fail_at {
        _ if !fits => Some(0),
        Some(k) => Some(k as usize % (strips_total + 2)),
        None => None,
    };
    let pushed = fail_at.map_or(strips_total, |k| (k + 1).min(strips_total));
    let want = if rows == 0 {
        Vec::new()
    } else {
        expected::<S, P, W>(frame, rows, pushed, bg, clear_z32, use_depth)
    };
    let want_err: Option<Error> = if rows == 0 {
        Some(Error::ColorBufferSize {
            expected: w,
            actual: len,
        })
    } else if use_depth && dlen < w * rows as usize {
        Some(Error::DepthBufferSize {
            expected: w * rows as usize,
            actual: dlen,
        })
    } else {
        None
    };
    let mut target = Rec::<T> {
        size: Size::new(config.width, h),
        calls: Vec::new(),
        fail_at,
        iter_used: false,
    };
    let mut scenes = 0usize;
    macro_rules! go {
        ($drawer:expr) => {{
            let mut drawer = $drawer.with_origin(origin);
            if d.clear_kind % 3 != 0 {
                drawer = drawer.with_clear_depth(clear_z32);
            }
            let _ = format!("{drawer:?}");
            assert_eq!(drawer.strip_rows(config.width) as usize, len / w);
            assert_eq!(drawer.strip_rows(0), 0);
            if d.immediate {
                let mut scene = |sr: &mut microraster::StripRenderer<'_, P, _, S>| {
                    scenes += 1;
                    for p in preps {
                        submit_strip(sr, p, Way::Main);
                    }
                };
                if S == 8 && d.extra & 1 == 0 {
                    let mut scene8 = |sr: &mut microraster::StripRenderer<'_, P, _, 8>| {
                        scenes += 1;
                        for p in preps {
                            submit_strip(sr, p, Way::Main);
                        }
                    };
                    drawer.draw(&mut target, config, &mut scene8)
                } else {
                    drawer.draw_subpixel::<_, _, S>(&mut target, config, &mut scene)
                }
            } else {
                drawer.draw_frame(&mut target, frame)
            }
        }};
    }
    let r = if use_depth {
        go!(StripDrawer::new(&mut color[..], &mut depth[..], bg))
    } else {
        go!(StripDrawer::new(&mut color[..], NoDepth, bg))
    };
    assert!(!target.iter_used, "StripDrawer used draw_iter");
    crate::debug(|| {
        format!(
            "arm: drawer {} {} depth={use_depth} rows={rows} origin={origin:?} {:?}",
            core::any::type_name::<P>(),
            core::any::type_name::<T>(),
            r.map(|s| s.pixels_written)
        )
    });
    if let Some(e) = want_err {
        assert_eq!(r, Err(DrawError::Render(e)));
        assert_eq!((target.calls.len(), scenes), (0, 0), "a render error drew");
        assert!(
            color.iter().all(|&p| p == P::GUARD),
            "a render error wrote colour"
        );
        assert!(
            depth.iter().all(|&z| z == W::GUARD),
            "a render error wrote depth"
        );
        return;
    }
    assert_eq!(target.calls.len(), pushed, "strips pushed: {r:?}");
    if d.immediate {
        assert_eq!(scenes, pushed, "scene calls");
    }
    match fail_at {
        Some(k) if k < strips_total => assert_eq!(r, Err(DrawError::Target(k))),
        _ => {
            let total: u64 = want.iter().map(|s| s.3).sum();
            assert_eq!(r.map(|s| s.pixels_written), Ok(total));
        }
    }
    for (i, ((area, got), (y0, y1, px, _))) in target.calls.iter().zip(&want).enumerate() {
        let top = Point::new(origin.x, origin.y.saturating_add(*y0 as i32));
        assert_eq!(
            *area,
            Rectangle::new(top, Size::new(config.width, y1 - y0)),
            "strip {i}: area"
        );
        assert_eq!(got.len(), px.len(), "strip {i}: pixel count");
        for (k, (g, p)) in got.iter().zip(px).enumerate() {
            assert_eq!(*g, T::from(*p), "strip {i} pixel {k}");
        }
    }
}
