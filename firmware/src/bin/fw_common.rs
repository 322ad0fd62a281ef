//! What every firmware binary shares: the defmt transport, and the ways out — panics and
//! hard faults exit QEMU through semihosting with failure, never hang.

#[cfg(feature = "rtt")]
use defmt_rtt as _;
#[cfg(not(feature = "rtt"))]
use defmt_semihosting as _;

use cortex_m_rt::{exception, ExceptionFrame};

#[exception]
unsafe fn HardFault(_frame: &ExceptionFrame) -> ! {
    exit(false)
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    defmt::error!("panic: {}", defmt::Display2Format(info));
    exit(false)
}

/// Ends the run: QEMU exits through semihosting (0 on success); on hardware with RTT
/// logging (`--features rtt`), the core stops at a breakpoint.
pub fn exit(success: bool) -> ! {
    #[cfg(not(feature = "rtt"))]
    {
        use cortex_m_semihosting::debug;
        debug::exit(if success {
            debug::EXIT_SUCCESS
        } else {
            debug::EXIT_FAILURE
        });
    }
    let _ = success;
    loop {
        cortex_m::asm::bkpt();
    }
}
