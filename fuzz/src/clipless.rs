//! The `clipless` target: the clipless mode (`RasterMode::Clipless`) on
//! arbitrary input, through strip renderers: it never panics, never writes
//! outside its rows, and draws the whole window and the input's split of
//! it alike (ids and `u32` depth), bit for bit.

use crate::{frame_config, prepare, rows, submit_prep, valid_size, Guarded, Input, Prep, Way};
use microraster::{Config, RasterMode, StripRenderer, TriangleId};

/// Draws rows `a..b` of the clipless frame: ids and depth.
fn draw(config: Config, preps: &[Prep], a: u32, b: u32) -> (Vec<TriangleId>, Vec<u32>) {
    let len = config.width as usize * (b - a) as usize;
    let mut c = Guarded::new(len, TriangleId(0), TriangleId(0x5a5a_5a5a));
    let mut d = Guarded::new(len, u32::MAX, 0x5a5a_5a5a);
    {
        let (cs, ds) = (c.inner(), d.inner());
        let mut sr =
            StripRenderer::<TriangleId, [u32], 8>::with_subpixel_bits(config, a, b, cs, ds)
                .expect("strip renderer");
        for p in preps {
            let r = submit_prep::<8, _>(&mut sr, p, Way::Main);
            assert_eq!(r, Ok(()), "a strip renderer refused a submission");
        }
    }
    c.check_guards();
    d.check_guards();
    (c.get().to_vec(), d.get().to_vec())
}

/// Runs one input.
pub fn run_clipless(input: &Input) {
    let clipping = frame_config(input);
    if !valid_size(&clipping) {
        return;
    }
    let config = Config {
        mode: RasterMode::Clipless,
        ..clipping
    };
    // The vertex stage does not depend on the mode (a frame, which the
    // clipless mode refuses, prepares processed meshes).
    let mut preps = prepare::<8>(input, clipping);
    if let Some(last) = preps.iter().rposition(|p| matches!(p, Prep::Clear)) {
        preps.drain(..=last);
    }
    let (y0, y1) = rows(&input.rest, &config);
    let whole = draw(config, &preps, y0, y1);
    let (mut ids, mut depth) = (Vec::new(), Vec::new());
    let mut y = y0;
    let mut k = 0;
    while y < y1 {
        let step = input
            .rest
            .splits
            .get(k)
            .map_or(y1 - y, |&s| s.max(1) as u32);
        let e = (y + step).min(y1);
        let (c, d) = draw(config, &preps, y, e);
        ids.extend(c);
        depth.extend(d);
        y = e;
        k += 1;
    }
    assert!(whole.0 == ids, "a split changed the ids");
    assert!(whole.1 == depth, "a split changed the depth");
}
