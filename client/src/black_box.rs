//! [`BlackBox`]: what a device kept of its run before its last reset — what stopped it,
//! what ended it, the reset's cause and its last ticks — read part by part
//! ([`crate::Device::black_box`]; docs/protocol.md, "BlackBox").

use mccs_link::black_box::{BlackBoxPart, BoxTick};
use std::fmt;

/// A device's record of its last run.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct BlackBox {
    /// What the first part said of the run (its ticks aside).
    pub head: BlackBoxPart,
    /// The ticks kept, oldest first.
    pub ticks: Vec<BoxTick>,
}

/// The reset flags' names (the STM32F4's RCC_CSR, bits 25–31).
const RESET_FLAGS: [(u32, &str); 7] = [
    (1 << 25, "BOR"),
    (1 << 26, "PIN"),
    (1 << 27, "POR"),
    (1 << 28, "SFT"),
    (1 << 29, "IWDG"),
    (1 << 30, "WWDG"),
    (1 << 31, "LPWR"),
];

impl BlackBox {
    /// Whether the device kept a record (false after a power-on).
    pub fn kept(&self) -> bool {
        self.head.kept
    }

    /// The reset's flags by name, `+`-joined (`none` where the chip reported none).
    pub fn reset_names(&self) -> String {
        let names: Vec<&str> = RESET_FLAGS
            .iter()
            .filter(|(bit, _)| self.head.reset_flags & bit != 0)
            .map(|&(_, n)| n)
            .collect();
        if names.is_empty() {
            "none".into()
        } else {
            names.join("+")
        }
    }

    /// The CSV of its ticks' columns (docs/link.md).
    pub const CSV_HEADER: &'static str =
        "tick,count_a,count_b,count_c,fx_n,fy_n,fz_n,duty_a,duty_b,duty_c,gain,flags";

    /// A tick's force, N per axis (kept in mN).
    pub fn force_n(t: &BoxTick) -> [f64; 3] {
        t.force_mn.map(|mn| mn as f64 / 1000.0)
    }

    /// A tick's duties, −1 … 1 (kept in Q15).
    pub fn duties(t: &BoxTick) -> [f64; 3] {
        t.duty_q15.map(|q| q as f64 / 32_768.0)
    }

    /// A tick's link gain, 0 … 1.
    pub fn gain(t: &BoxTick) -> f64 {
        t.gain as f64 / mccs_link::scale::GAIN_FULL as f64
    }

    /// One tick as a CSV row (forces in N, duties and the gain as fractions of full).
    pub fn csv_row(t: &BoxTick) -> String {
        let ([fx, fy, fz], [da, db, dc]) = (Self::force_n(t), Self::duties(t));
        format!(
            "{},{},{},{},{fx},{fy},{fz},{da:.5},{db:.5},{dc:.5},{:.5},{}",
            t.tick,
            t.counts[0],
            t.counts[1],
            t.counts[2],
            Self::gain(t),
            t.flags
        )
    }

    /// Puts a part in: the first gives the head; each must agree with it and start where
    /// the ticks so far end. The ticks still to read (0: whole), or why the part does
    /// not fit (the device reset while it was read, say).
    pub(crate) fn take(&mut self, part: &BlackBoxPart) -> Result<usize, String> {
        let mut head = *part;
        head.first = 0;
        head.part_ticks = Default::default();
        if self.ticks.is_empty() && self.head == BlackBoxPart::default() {
            self.head = head;
        } else if head != self.head {
            return Err("the black box changed while it was read (the device reset?)".into());
        }
        if part.first as usize != self.ticks.len() {
            return Err(format!(
                "a part from tick {} where {} were read",
                part.first,
                self.ticks.len()
            ));
        }
        let total = part.ticks as usize;
        let n = (total - self.ticks.len().min(total)).min(part.part_ticks.len());
        self.ticks.extend_from_slice(&part.part_ticks[..n]);
        Ok(total - self.ticks.len().min(total))
    }
}

impl fmt::Display for BlackBox {
    /// [`BlackBox::line`] with the part's code.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.line(&self.head.part.to_string()))
    }
}

impl BlackBox {
    /// One line: `blackbox kept=false`, or what stopped the run (the part as `part`
    /// says it: a board's name for its code), what ended it, the reset and the ticks
    /// kept.
    pub fn line(&self, part: &str) -> String {
        let h = &self.head;
        if !h.kept {
            return "blackbox kept=false".into();
        }
        format!(
            "blackbox kept=true stopped_by={} part={} stop_tick={} ended_by={} end_tick={} pc=0x{:08x} reset={} reset_flags=0x{:08x} ticks={}",
            h.cause.name(),
            part,
            h.tick,
            h.end.name(),
            h.end_tick,
            h.pc,
            self.reset_names(),
            h.reset_flags,
            self.ticks.len()
        )
    }
}
