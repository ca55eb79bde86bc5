//! Counting instructions with SysTick under QEMU.
//!
//! QEMU has no cycle counter, but with `-icount shift=0` each instruction
//! advances virtual time by exactly 1 ns, and SysTick (on the processor
//! clock) counts virtual time, deterministically. [`Clock::now`] extends the
//! 24-bit down-counter to 64 bits (it must be read at least once per
//! 2^24 ticks, which the firmware does once per strip), and
//! [`Clock::instructions_per_tick`] measures the ratio on a loop of known
//! length instead of trusting the board's clock frequency.

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;

const RELOAD: u32 = 0x00ff_ffff;

/// A 64-bit tick counter on SysTick.
pub struct Clock {
    _syst: SYST,
    wraps: u64,
    last: u32,
}

impl Clock {
    /// Starts SysTick on the processor clock, counting down from 2^24 - 1.
    pub fn start(mut syst: SYST) -> Clock {
        syst.disable_interrupt();
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(RELOAD);
        syst.clear_current();
        syst.enable_counter();
        Clock {
            _syst: syst,
            wraps: 0,
            last: RELOAD,
        }
    }

    /// Ticks since [`Clock::start`].
    pub fn now(&mut self) -> u64 {
        let v = SYST::get_current();
        if v > self.last {
            self.wraps += 1;
        }
        self.last = v;
        (self.wraps << 24) + u64::from(RELOAD - v)
    }

    /// Instructions per tick as `(instructions, ticks)`, measured on a
    /// loop of two instructions per iteration, as the difference of two
    /// lengths (which cancels the constant cost of reading the clock).
    pub fn instructions_per_tick(&mut self) -> (u64, u64) {
        let (short, long) = (100_000u32, 1_100_000u32);
        let t_short = self.time(|| spin(short));
        let t_long = self.time(|| spin(long));
        (u64::from(2 * (long - short)), (t_long - t_short).max(1))
    }

    fn time(&mut self, f: impl FnOnce()) -> u64 {
        let t0 = self.now();
        f();
        self.now() - t0
    }
}

/// `n` iterations of `subs; bne`: exactly `2 n` instructions.
#[inline(never)]
fn spin(n: u32) {
    // SAFETY: a register countdown; touches no memory and no stack.
    unsafe {
        core::arch::asm!(
            "2:",
            "subs {0}, #1",
            "bne 2b",
            inout(reg) n => _,
            options(nomem, nostack),
        );
    }
}
