//! What differs between QEMU and a real board: the defmt transport, how the
//! program ends, and what a panic or a hard fault does.
//!
//! - feature `qemu` (default): defmt frames go to semihosting stdout
//!   (`defmt-semihosting`) and the program ends with a semihosting exit code,
//!   so QEMU's own exit status is the firmware's verdict.
//! - feature `rtt`: defmt frames go to an RTT buffer (`defmt-rtt`) read by
//!   probe-rs; "ending" means holding attitude forever, and a panic stops the
//!   core on a breakpoint, which probe-rs reports as a failure.

#[cfg(all(feature = "qemu", feature = "rtt"))]
compile_error!("features `qemu` and `rtt` select two defmt transports: enable exactly one");
#[cfg(not(any(feature = "qemu", feature = "rtt")))]
compile_error!("enable one defmt transport: feature `qemu` (default) or `rtt`");

#[cfg(feature = "rtt")]
use defmt_rtt as _;
#[cfg(feature = "qemu")]
use defmt_semihosting as _;

use cortex_m_rt::{exception, ExceptionFrame};

/// How a run ended, as the outside world sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum Outcome {
    /// Every commanded target was reached within tolerance and time.
    Success,
    /// Something was not reached, the table was refused, or the program failed.
    Failure,
}

/// Ends the program with `outcome`.
///
/// Under QEMU this is a semihosting exit (status 0 on success, 1 otherwise).
/// On hardware there is nothing to exit to: the core waits for a debugger
/// after a failure (breakpoint) and otherwise sleeps.
pub fn finish(outcome: Outcome) -> ! {
    #[cfg(feature = "qemu")]
    {
        use cortex_m_semihosting::debug;
        debug::exit(match outcome {
            Outcome::Success => debug::EXIT_SUCCESS,
            Outcome::Failure => debug::EXIT_FAILURE,
        });
    }
    #[cfg(feature = "rtt")]
    if outcome == Outcome::Failure {
        cortex_m::asm::bkpt();
    }
    loop {
        cortex_m::asm::wfi();
    }
}

/// Reports a panic through defmt and ends the program with a failure.
#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    defmt::error!("panic: {}", defmt::Display2Format(info));
    finish(Outcome::Failure)
}

/// Reports a hard fault through defmt and ends the program with a failure
/// (without this, cortex-m-rt's default handler would spin and QEMU would hang
/// until the test's timeout).
// SAFETY: cortex-m-rt requires the HardFault handler to be an `unsafe fn`; it
// is only ever entered by the hardware, with a valid exception frame.
#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    defmt::error!(
        "hard fault at pc={=u32:#010x} lr={=u32:#010x}",
        frame.pc(),
        frame.lr()
    );
    finish(Outcome::Failure)
}
