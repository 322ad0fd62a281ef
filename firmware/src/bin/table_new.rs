//! What a force table built at a device's start-up costs, measured in QEMU under
//! `-icount` as the bench measures (its `harness`): `ForceTable64::new` on Table 2 (the
//! builder's best placement, measured against the `f64` law in software floating point,
//! held to the product's bound), once. The table must be, bit for bit, the one
//! `mccs table` emits (`tables/table2.rs`), or the run fails. Prints
//! `BENCH core=<c> case=table_new instructions=<n> ms_at_clock=<ms> stack_bytes=<b>` (the
//! whole stack the run used, this firmware's own frames included: the free stack is
//! painted before it); its flash is the code only `mccs_firmware::entry::table_new`
//! reaches (`scripts/code_size.py`).
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("table_new is firmware: run it in QEMU (scripts/bench.sh)");
    std::process::exit(2);
}

#[cfg(target_os = "none")]
#[path = "fw_common.rs"]
mod fw_common;

#[cfg(target_os = "none")]
mod stack_paint;

#[cfg(target_os = "none")]
#[path = "bench/harness.rs"]
#[allow(dead_code)] // (`Harness::measure`: the bench's, not used here)
mod harness;

#[cfg(target_os = "none")]
mod firmware {
    use super::fw_common::exit;
    use super::harness;
    use super::stack_paint;
    use core::hint::black_box;
    use cortex_m_rt::entry;
    use mccs::{ForceTable64, Params};
    use mccs_firmware::target::CORE;

    static EMITTED: ForceTable64 = include!("../../../tables/table2.rs");

    #[entry]
    fn main() -> ! {
        let Some(cp) = cortex_m::Peripherals::take() else {
            exit(false)
        };
        let h = harness::start(cp.SYST);
        let mut built = None;
        stack_paint::paint();
        let instructions = h.measure_long(|| {
            built = Some(black_box(mccs_firmware::entry::table_new(black_box(
                &Params::TABLE2,
            ))));
        });
        let (stack, _) = stack_paint::used_and_free();
        let same = matches!(built, Some(Ok(t)) if t == EMITTED);
        defmt::println!(
            "BENCH core={=str} case=table_new instructions={=u64} ms_at_clock={=u64} stack_bytes={=u32}",
            CORE.name(),
            instructions,
            CORE.ms_at_clock(instructions),
            stack
        );
        if !same {
            defmt::error!("table_new: the table built is not the one mccs table emits");
        }
        exit(same)
    }
}
