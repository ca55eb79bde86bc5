//! Timing statistics of `microraster bench`: medians, summaries, timed loops.
//!
//! Design note: every figure the benchmark prints is a median (or min, mean,
//! max) over frames timed one by one with [`Instant`]; nothing here knows
//! what is being timed. Untimed warm-up frames come first and are dropped.

use serde::Serialize;
use std::time::Instant;

/// Median of `v` (mean of the middle two for an even count); NaN if empty.
pub fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        (s[n / 2 - 1] + s[n / 2]) * 0.5
    }
}

/// The smallest value of `v` (infinity if empty).
pub fn min(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::INFINITY, f64::min)
}

/// Median, min, mean and max of a list of times in milliseconds.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Summary {
    /// Median.
    #[serde(rename = "median_ms")]
    pub median: f64,
    /// Minimum.
    #[serde(rename = "min_ms")]
    pub min: f64,
    /// Mean.
    #[serde(rename = "mean_ms")]
    pub mean: f64,
    /// Maximum.
    #[serde(rename = "max_ms")]
    pub max: f64,
}

impl Summary {
    /// Summarises `v`.
    pub fn of(v: &[f64]) -> Summary {
        Summary {
            median: median(v),
            min: min(v),
            mean: v.iter().sum::<f64>() / v.len() as f64,
            max: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }

    /// As a JSON object, to add fields to.
    pub fn json(&self) -> serde_json::Value {
        serde_json::to_value(self).unwrap_or_default()
    }
}

/// Runs `warmup` untimed and `frames` timed calls of `f(k)` (k counting
/// from 0 over both) and returns the timed ones' milliseconds.
pub fn time_frames<F: FnMut(u32) -> Result<(), String>>(
    warmup: u32,
    frames: u32,
    mut f: F,
) -> Result<Vec<f64>, String> {
    let mut out = Vec::with_capacity(frames as usize);
    for k in 0..warmup + frames {
        let t = Instant::now();
        f(k)?;
        if k >= warmup {
            out.push(ms(t));
        }
    }
    Ok(out)
}

/// Milliseconds since `t`.
pub fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_and_summary() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(&[]).is_nan());
        let s = Summary::of(&[1.0, 2.0, 6.0]);
        assert_eq!((s.median, s.min, s.mean, s.max), (2.0, 1.0, 3.0, 6.0));
        let j = s.json();
        assert_eq!(j["median_ms"], 2.0);
        assert_eq!(j["max_ms"], 6.0);
    }
}
