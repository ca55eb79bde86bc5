//! Progress of long benchmark runs, on stderr.
//!
//! Design note: stdout carries only the JSON, so progress goes to stderr,
//! and only once a run has taken longer than the interval (2 s, or
//! `MICRORASTER_PROGRESS_MS`): short runs print nothing. On a terminal it is
//! one line rewritten in place; otherwise (CI logs, pipes) a plain line per
//! interval, so a log shows that a long run is alive. No crate is needed for
//! this: `std::io::IsTerminal` tells the two apart.

use std::io::{IsTerminal, Write};
use std::time::{Duration, Instant};

/// The interval without `MICRORASTER_PROGRESS_MS`.
pub const DEFAULT_INTERVAL: Duration = Duration::from_secs(2);

/// Prints progress lines at most once per interval.
#[derive(Debug)]
pub struct Progress {
    tty: bool,
    interval: Duration,
    last: Instant,
    dirty: bool,
}

impl Progress {
    /// Stderr's kind and the interval from `MICRORASTER_PROGRESS_MS`.
    pub fn from_env() -> Progress {
        let interval = std::env::var("MICRORASTER_PROGRESS_MS")
            .ok()
            .and_then(|v| v.trim().parse::<u64>().ok())
            .map_or(DEFAULT_INTERVAL, Duration::from_millis);
        Progress {
            tty: std::io::stderr().is_terminal(),
            interval,
            last: Instant::now(),
            dirty: false,
        }
    }

    /// Frame `done` of `total` of `what` is starting.
    pub fn tick(&mut self, what: &str, done: u32, total: u32) {
        if self.last.elapsed() >= self.interval {
            self.line(&format!("{what}: frame {}/{total}", done + 1));
        }
    }

    /// A new stage `what` is starting.
    pub fn note(&mut self, what: &str) {
        if self.last.elapsed() >= self.interval {
            self.line(what);
        }
    }

    fn line(&mut self, text: &str) {
        let mut err = std::io::stderr().lock();
        let _ = if self.tty {
            write!(err, "\r\x1b[2Kmicroraster bench: {text}")
        } else {
            writeln!(err, "microraster bench: {text}")
        };
        let _ = err.flush();
        self.dirty = self.tty;
        self.last = Instant::now();
    }

    /// Ends the updating line on a terminal.
    pub fn finish(&mut self) {
        if self.dirty {
            eprintln!();
            self.dirty = false;
        }
    }
}
