//! `BoardConfig`: the board's constants in one place — clocks, the tick, the SPI and PWM
//! rates, the watchdog, the encoder's mounting, the motor's constant and the patch — with
//! the checks that keep them consistent, and the clock arithmetic of the HAL they feed
//! (SPI divider, PWM resolution, tick timer) so that a host test can hold them to the
//! parts' limits. The pin map is type-level (the HAL's pins are types): `src/pins.rs`,
//! one table with this one in docs/firmware.md.

use mccs::arith::Integrator;
use mccs::{Coupling, SolverConfig};
use mccs_firmware::drivers::as5047p::EncoderConfig;
use mccs_firmware::drivers::pwm_motor::{MotorConfig, MotorConfigError};

/// The AS5047P's fastest SPI clock, Hz (datasheet: 10 MHz).
pub const AS5047P_MAX_SPI_HZ: u32 = 10_000_000;
/// The tick timer's counter rate, Hz: the tick statistics are in µs.
pub const TICK_COUNTER_HZ: u32 = 1_000_000;
/// The timer clock QEMU 7.2 gives the STM32F4 timers whatever the RCC says (its
/// `stm32f2xx_timer` model runs at 1 GHz of virtual time).
pub const QEMU_TIMER_CLOCK_HZ: u32 = 1_000_000_000;
/// The STM32F405's APB2 limit, Hz (SPI1's clock, TIM1's at ×2).
pub const PCLK2_MAX_HZ: u32 = 84_000_000;
/// Grid spacing of the patch and the tissue, mm.
pub const SPACING_MM: f64 = 2.5;
/// The STM32F405's APB1 limit, Hz (TIM2's clock at ×2).
pub const PCLK1_MAX_HZ: u32 = 42_000_000;

/// Everything a port to another board changes, apart from the pins.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoardConfig {
    /// HSE crystal, Hz (8 MHz on most STM32F405 boards: 4 … 26 MHz).
    pub hse_hz: u32,
    /// Core clock from the PLL, Hz (24 … 168 MHz).
    pub sysclk_hz: u32,
    /// Haptic tick rate, Hz (TIM2 update interrupt; the solver's tick): 100 … 10,000,
    /// dividing 1 MHz exactly.
    pub tick_hz: u32,
    /// SPI1 clock asked of the HAL, Hz. The HAL divides APB2 by a power of two and
    /// rounds the divider *down* (asking 10 MHz of 84 MHz gives 10.5 MHz), so this is
    /// held to the clock it gives: at most the AS5047P's 10 MHz.
    pub spi_request_hz: u32,
    /// PWM frequency on TIM1 CH1, Hz (20 kHz: above hearing). At least 1,000 duty steps.
    pub pwm_hz: u32,
    /// Independent watchdog timeout, ms: 10 ticks … 10,000 ms. LSI is 17–47 kHz
    /// (nominally 32 kHz), so the real timeout is 0.68 … 1.9 × this.
    pub watchdog_ms: u32,
    /// Encoder angle at zero travel, counts (0 … 16383).
    pub encoder_zero: u16,
    /// Probe travel per encoder count, mm (|x| < 0.01; the sign is the direction):
    /// `2π r / (16384 i)` for a lever of radius r mm through a capstan of ratio i.
    pub mm_per_count: f64,
    /// The fastest the probe moves, mm/s: the encoder's plausibility check.
    pub max_speed_mm_s: f64,
    /// The lever's travel either side of zero, mm (0 < x ≤ 1000): the encoder follows it
    /// over whole turns, and a lever beyond it is a fault (the safe state).
    pub travel_mm: f64,
    /// Encoder frames between diagnostic reads (DIAAGC), 0 for never.
    pub diag_every: u16,
    /// Bad encoder frames in a row tolerated before the safe state.
    pub max_bad_frames: u32,
    /// Force at the probe at 100 % duty, N (0.001 … 1024): `k_t · I_max · i / (r/1000)`,
    /// for a current-mode driver (duty ∝ current ∝ torque; a plain H-bridge's torque
    /// also falls with the motor's speed: docs/firmware.md, "The motor driver").
    pub force_at_full_duty: f64,
    /// The patch: N × N surface nodes (the standard patch, 2.5 mm spacing): 3 …
    /// [`MAX_GRID`] (10).
    pub grid: usize,
    /// The integrator (`--integrator`): the symplectic option, whose 2 substeps a 1 kHz
    /// tick at N = 10 takes where the paper's improved Euler takes 3 (docs/arm.md, "The
    /// trainer tick").
    pub integrator: Integrator,
    /// Haptic mass of each free node, g (> 0; `mccs patch`/`replay`'s `--node-mass`).
    pub node_mass_g: f64,
    /// Relative damping of each spring, N·s/m (`--spring-damping`).
    pub spring_damping: f64,
    /// The probe coupling's stiffness, N/mm (> 0, ≤ 1000; `--coupling-stiffness`): with
    /// the tissue, what a press feels like (docs/cli.md, "From a sample to what a hand
    /// feels").
    pub coupling_stiffness: f64,
    /// The probe coupling's damping, N·s/m (0 … 1000; `--coupling-damping`).
    pub coupling_damping: f64,
    /// The largest force per axis the controller renders, N (> 0, at most
    /// `force_at_full_duty`, which the motor saturates at; `--max-force`).
    pub max_force: f64,
    /// Ticks a QEMU run (`--features qemu`) lasts before its SUMMARY.
    pub qemu_ticks: u32,
    /// The host link's baud rate on USART2, 8N1 (within 1 % of what APB1 can make:
    /// 1,000,000 is exact at 42 MHz).
    pub baud: u32,
    /// The force's ramp from zero after `Arm`, a start or homing, ms (0 … 5,000).
    pub ramp_ms: u32,
    /// TIM1's break input on PB12 (`safe_stop::BreakInput`): the emergency stop's and
    /// the amplifiers' fault chain, which cuts every PWM output in hardware. Default
    /// active low (fail-safe: an open chain stops the drive; docs/safety.md).
    pub break_input: crate::safe_stop::BreakInput,
    /// Overruns in a row that put the device in its safe state (1 … 1,000).
    pub max_overruns_in_row: u32,
    /// The pose's slew limits: mm/s per axis of its origin (1 … 1,000), degrees/s of
    /// its rotation (1 … 3,600).
    pub pose_speed_mm_s: u16,
    /// See `pose_speed_mm_s`.
    pub pose_turn_deg_s: u16,
    /// Where a pose may put the tissue's origin, mm in the device's frame (the arm: its
    /// tissue frame of `devices/*.toml`): the low corner, then the high one, each within
    /// ±100 mm.
    pub workspace_mm: [[f64; 3]; 2],
    /// The roaming tissue's size, nodes (the arm; `grid` … 64 a side, within ±100 mm at
    /// the patch's spacing).
    pub tissue_nodes: [usize; 2],
    /// Its friction, static and kinetic (0 … 2, `mu_k ≤ mu_s`).
    pub mu_s: f64,
    /// See `mu_s`.
    pub mu_k: f64,
    /// Instructions a tick may spend (half a tick at the core's clock: 84,000 at
    /// 168 MHz), what it costs besides its substeps, and what a substep costs: measured
    /// on the arm board's own run at N = 10 (docs/arm.md, "The trainer tick"), whose
    /// worst tick the test command holds within `tick_base_cost + substeps ×
    /// substep_cost`, with a host on the link too. The base is that run's rest
    /// ([`TICK_REST_COST`]) and the link's work at most ([`LINK_WORK_COST`]). A tissue
    /// whose tick would pass the budget is refused.
    pub tick_budget: u32,
    /// See `tick_budget`.
    pub tick_base_cost: u32,
    /// See `tick_budget`.
    pub substep_cost: u32,
    /// Steps of a tissue's stability check run between two polls of the link: at most
    /// 5 ms of the M4F at 168 MHz at N = 10 (`link::device::a_slice_of_a_tissue_check_
    /// holds_the_main_loop_under_5_ms` holds them to the bench's cost of a step).
    pub check_steps_per_poll: u32,
}

/// The arm board's tick besides its substeps and the link's work, instructions: its
/// simulated arm's palpation in QEMU less its 2 substeps (docs/arm.md, "The trainer
/// tick").
pub const TICK_REST_COST: u32 = 12_900;

/// The link's work in one tick at most, instructions: its share of every tick, a
/// tissue's swap and a mesh's capture, which may fall on one tick, each at its budget in
/// bench/budgets.txt (`tick_link`, `link_swap_n10`, `link_mesh_n10`; a test holds the
/// sum to that file).
pub const LINK_WORK_COST: u32 = 800 + 3_200 + 3_600;

/// The largest patch the board's controller holds: N = 10 (the trainer's patch, issue 60:
/// its tick fits half of a 1 kHz tick with the symplectic option's 2 substeps;
/// docs/arm.md, "The trainer tick").
pub const MAX_GRID: usize = 10;

/// The STM32F405 board: 8 MHz crystal, 168 MHz, a 1 kHz tick, the AS5047P at 5.25 MHz,
/// 20 kHz PWM, a 50 ms watchdog; a 75 mm lever on a 10:1 capstan, a 3 N motor, the
/// force held to it; the N = 10 patch (the symplectic option's 2 substeps), the solver's
/// default coupling.
pub const BOARD: BoardConfig = BoardConfig {
    hse_hz: 8_000_000,
    sysclk_hz: 168_000_000,
    tick_hz: 1000,
    spi_request_hz: 7_000_000,
    pwm_hz: 20_000,
    watchdog_ms: 50,
    encoder_zero: 0,
    mm_per_count: 0.002876,
    max_speed_mm_s: 500.0,
    travel_mm: 40.0,
    diag_every: 100,
    max_bad_frames: 8,
    force_at_full_duty: 3.0,
    grid: 10,
    integrator: Integrator::SymplecticDamped,
    node_mass_g: 5.0,
    spring_damping: 1.0,
    coupling_stiffness: 1.0,
    coupling_damping: 0.5,
    max_force: 3.0,
    qemu_ticks: 1000,
    baud: mccs_link::rates::DEFAULT_BAUD,
    ramp_ms: 500,
    break_input: crate::safe_stop::BreakInput::ActiveLow,
    max_overruns_in_row: 10,
    pose_speed_mm_s: 200,
    pose_turn_deg_s: 180,
    workspace_mm: [[-50.0, -50.0, -40.0], [50.0, 50.0, 40.0]],
    tissue_nodes: [64, 64],
    mu_s: 0.6,
    mu_k: 0.4,
    tick_budget: 84_000,
    tick_base_cost: TICK_REST_COST + LINK_WORK_COST,
    substep_cost: 31_200,
    check_steps_per_poll: 12,
};

/// A board constant out of its range: which one, in words.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoardConfigError {
    /// `hse_hz` is not 4 … 26 MHz.
    Hse,
    /// `sysclk_hz` is not 24 … 168 MHz.
    Sysclk,
    /// `tick_hz` is not 100 … 10,000 Hz dividing 1 MHz.
    Tick,
    /// The SPI clock the HAL would give is above the AS5047P's 10 MHz, or zero.
    SpiTooFast,
    /// The PWM would have fewer than 1,000 duty steps, or `pwm_hz` is zero.
    PwmResolution,
    /// `watchdog_ms` is not 10 ticks … 10,000 ms.
    Watchdog,
    /// `encoder_zero` is above 16383, or `mm_per_count` is not finite and 0 < |x| < 0.01,
    /// or `travel_mm` is not 0 < x ≤ 1000 (and within 2²⁴ counts).
    Encoder,
    /// `max_speed_mm_s` is not a finite positive number.
    Speed,
    /// The motor constant.
    Motor(MotorConfigError),
    /// `grid` is not 3 … 10 (the controller's capacity), or the mass or damping is not
    /// a finite positive number.
    Patch,
    /// The coupling's stiffness, damping or force clamp is out of the solver's range.
    Coupling,
    /// `max_force` is over `force_at_full_duty`: the motor would saturate below the
    /// clamp, without a word.
    ForceClamp,
    /// `baud` is not within 1 % of what USART2 makes at APB1's clock, or outside
    /// 9,600 … 2,625,000.
    Baud,
    /// `ramp_ms`, `max_overruns_in_row` or the pose's limits out of range.
    Link,
    /// The workspace, the tissue's size or its friction out of range.
    Tissue,
    /// The tick's budget or costs: zero, or no substep fits.
    Budget,
}

impl BoardConfigError {
    /// The message: one source for `Display` and the `defmt` impl.
    pub const fn message(&self) -> &'static str {
        match self {
            Self::Hse => "hse_hz: must be 4 … 26 MHz",
            Self::Sysclk => "sysclk_hz: must be 24 … 168 MHz",
            Self::Tick => "tick_hz: must be 100 … 10000 Hz and divide 1 MHz",
            Self::SpiTooFast => {
                "spi_request_hz: the HAL's divider would clock the AS5047P above 10 MHz (or not at all)"
            }
            Self::PwmResolution => "pwm_hz: fewer than 1000 duty steps at this timer clock",
            Self::Watchdog => "watchdog_ms: must be 10 ticks … 10000 ms",
            Self::Encoder => {
                "encoder_zero ≤ 16383, 0 < |mm_per_count| < 0.01, 0 < travel_mm ≤ 1000 and within 2^24 counts"
            }
            Self::Speed => "max_speed_mm_s: must be finite and positive",
            Self::Motor(_) => "force_at_full_duty: must be 0.001 … 1024 N",
            Self::Patch => "grid 3 … 10, node_mass_g and spring_damping finite and positive",
            Self::Coupling => "coupling_stiffness > 0 and ≤ 1000 N/mm, coupling_damping 0 … 1000 N·s/m, max_force > 0 N",
            Self::ForceClamp => "max_force: must be at most force_at_full_duty (the motor saturates there)",
            Self::Baud => "baud: must be 9600 … 2625000 and within 1 % of what USART2 makes at APB1's clock",
            Self::Link => "ramp_ms 0 … 5000, max_overruns_in_row 1 … 1000, pose_speed_mm_s 1 … 1000, pose_turn_deg_s 1 … 3600",
            Self::Tissue => "workspace_mm within ±100 mm (low ≤ high), tissue_nodes grid … 64 within ±100 mm, 0 ≤ mu_k ≤ mu_s ≤ 2",
            Self::Budget => "tick_budget, tick_base_cost, substep_cost > 0, one substep within the budget, check_steps_per_poll ≥ 1",
        }
    }
}

impl core::fmt::Display for BoardConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.message())
    }
}

/// The SPI clock the HAL gives for `request_hz` from a peripheral clock `pclk_hz`: the
/// divider `pclk / request` rounded *down* to a power of two (2 … 256), as
/// stm32f4xx-hal 0.22 picks it.
pub const fn spi_clock_hz(pclk_hz: u32, request_hz: u32) -> u32 {
    if request_hz == 0 {
        return 0;
    }
    let divider = match pclk_hz / request_hz {
        0..=2 => 2,
        3..=5 => 4,
        6..=11 => 8,
        12..=23 => 16,
        24..=47 => 32,
        48..=95 => 64,
        96..=191 => 128,
        _ => 256,
    };
    pclk_hz / divider
}

/// The PWM's duty steps (full scale) at `pwm_hz` from the timer clock, as the HAL sets
/// the timer (prescaler only when the period overflows 16 bits).
pub const fn pwm_max_duty(timer_clock_hz: u32, pwm_hz: u32) -> u32 {
    if pwm_hz == 0 || timer_clock_hz < pwm_hz {
        return 0;
    }
    let ticks = timer_clock_hz / pwm_hz;
    let psc = (ticks - 1) / (1 << 16);
    ticks / (psc + 1)
}

/// The tick timer's prescaler and auto-reload: the counter at [`TICK_COUNTER_HZ`]
/// (1 µs), an update every `1e6 / tick_hz` counts. `None` when the timer clock is not a
/// whole number of MHz (≤ 65.536 GHz) or the tick does not divide 1 MHz.
pub const fn tick_timer(timer_clock_hz: u32, tick_hz: u32) -> Option<(u16, u32)> {
    if tick_hz == 0
        || !timer_clock_hz.is_multiple_of(TICK_COUNTER_HZ)
        || timer_clock_hz < TICK_COUNTER_HZ
        || !TICK_COUNTER_HZ.is_multiple_of(tick_hz)
    {
        return None;
    }
    let psc = timer_clock_hz / TICK_COUNTER_HZ - 1;
    if psc > u16::MAX as u32 {
        return None;
    }
    Some((psc as u16, TICK_COUNTER_HZ / tick_hz - 1))
}

/// How far the baud rate USART2 makes from `pclk_hz` is from `baud`, parts per million:
/// oversampling by 16, its divider `pclk / baud` in sixteenths, rounded to nearest (as
/// the HAL sets `BRR`).
pub const fn usart_error_ppm(pclk_hz: u32, baud: u32) -> u32 {
    if baud == 0 {
        return u32::MAX;
    }
    // BRR = USARTDIV · 16 = pclk / baud, to nearest; the rate made is pclk / BRR.
    let brr = (pclk_hz as u64 + baud as u64 / 2) / baud as u64;
    if brr < 16 {
        return u32::MAX;
    }
    let made_micro = pclk_hz as u64 * 1_000_000 / brr;
    let want_micro = baud as u64 * 1_000_000;
    (made_micro.abs_diff(want_micro) * 1_000_000 / want_micro) as u32
}

/// The clocks the HAL sets from a [`BoardConfig`]: APB1 and APB2 at their limits (or
/// the core clock, if lower), timers at twice their bus clock when it is divided.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Clocks {
    /// Core clock, Hz.
    pub sysclk_hz: u32,
    /// APB2 (SPI1), Hz.
    pub pclk2_hz: u32,
    /// TIM1 (APB2 timers), Hz.
    pub tim1_hz: u32,
    /// TIM2 (APB1 timers), Hz.
    pub tim2_hz: u32,
    /// APB1 (USART2), Hz.
    pub pclk1_hz: u32,
}

impl Clocks {
    /// The clock tree for a core clock, as stm32f4xx-hal 0.22 sets it by default: each
    /// APB at its limit or below, its divider `⌈sysclk / limit⌉` rounded up to a power
    /// of two, its timers at twice its clock when divided.
    pub const fn for_sysclk(sysclk_hz: u32) -> Self {
        let (pclk1, tim2) = apb(sysclk_hz, PCLK1_MAX_HZ);
        let (pclk2, tim1) = apb(sysclk_hz, PCLK2_MAX_HZ);
        Self {
            sysclk_hz,
            pclk2_hz: pclk2,
            tim1_hz: tim1,
            tim2_hz: tim2,
            pclk1_hz: pclk1,
        }
    }
}

/// One APB bus: its clock and its timers' clock.
const fn apb(hclk_hz: u32, max_hz: u32) -> (u32, u32) {
    let divider = match hclk_hz.div_ceil(max_hz) {
        0 | 1 => 1,
        2 => 2,
        3..=5 => 4,
        6..=11 => 8,
        _ => 16,
    };
    let pclk = hclk_hz / divider;
    (pclk, if divider == 1 { pclk } else { 2 * pclk })
}

impl BoardConfig {
    /// Checks every constant against the parts' limits, at the clock tree it sets.
    pub fn check(&self) -> Result<(), BoardConfigError> {
        use BoardConfigError as E;
        self.check_clocks()?;
        let mpc = self.mm_per_count;
        if self.encoder_zero > 0x3FFF || !mpc.is_finite() || mpc == 0.0 || libm::fabs(mpc) >= 0.01 {
            return Err(E::Encoder);
        }
        let travel = self.travel_mm;
        if !(travel.is_finite() && travel > 0.0 && travel <= 1000.0)
            || travel / libm::fabs(mpc) > (1u32 << 24) as f64
        {
            return Err(E::Encoder);
        }
        if !(self.max_speed_mm_s.is_finite() && self.max_speed_mm_s > 0.0) {
            return Err(E::Speed);
        }
        MotorConfig::check(self.force_at_full_duty).map_err(E::Motor)?;
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !(3..=MAX_GRID).contains(&self.grid)
            || !positive(self.node_mass_g)
            || !positive(self.spring_damping)
        {
            return Err(E::Patch);
        }
        if self.solver().validate().is_err() {
            return Err(E::Coupling);
        }
        if self.max_force > self.force_at_full_duty {
            return Err(E::ForceClamp);
        }
        if self.ramp_ms > 5_000
            || !(1..=1_000).contains(&self.max_overruns_in_row)
            || !(1..=1_000).contains(&self.pose_speed_mm_s)
            || !(1..=3_600).contains(&self.pose_turn_deg_s)
        {
            return Err(E::Link);
        }
        self.check_tissue()?;
        if self.tick_budget == 0
            || self.tick_base_cost == 0
            || self.substep_cost == 0
            || self.check_steps_per_poll == 0
            || self.tick_base_cost.saturating_add(self.substep_cost) > self.tick_budget
        {
            return Err(E::Budget);
        }
        Ok(())
    }

    /// The clock tree's checks: the crystal, the system clock, the tick, the SPI, PWM and
    /// UART rates it gives, and the watchdog against the tick.
    fn check_clocks(&self) -> Result<(), BoardConfigError> {
        use BoardConfigError as E;
        if !(4_000_000..=26_000_000).contains(&self.hse_hz) {
            return Err(E::Hse);
        }
        if !(24_000_000..=168_000_000).contains(&self.sysclk_hz) {
            return Err(E::Sysclk);
        }
        if !(100..=10_000).contains(&self.tick_hz) || !TICK_COUNTER_HZ.is_multiple_of(self.tick_hz)
        {
            return Err(E::Tick);
        }
        let clocks = Clocks::for_sysclk(self.sysclk_hz);
        let spi = spi_clock_hz(clocks.pclk2_hz, self.spi_request_hz);
        if spi == 0 || spi > AS5047P_MAX_SPI_HZ {
            return Err(E::SpiTooFast);
        }
        if pwm_max_duty(clocks.tim1_hz, self.pwm_hz) < 1000 {
            return Err(E::PwmResolution);
        }
        if tick_timer(clocks.tim2_hz, self.tick_hz).is_none() {
            return Err(E::Tick);
        }
        let tick_ms = 1000.0 / self.tick_hz as f64;
        if (self.watchdog_ms as f64) < 10.0 * tick_ms || self.watchdog_ms > 10_000 {
            return Err(E::Watchdog);
        }
        if !(9_600..=2_625_000).contains(&self.baud)
            || usart_error_ppm(clocks.pclk1_hz, self.baud) > 10_000
        {
            return Err(E::Baud);
        }
        Ok(())
    }

    /// The tissue's checks: its workspace within ±100 mm, its sides from the patch's
    /// grid to 64 nodes and within ±100 mm, and 0 ≤ μk ≤ μs ≤ 2.
    fn check_tissue(&self) -> Result<(), BoardConfigError> {
        let [lo, hi] = self.workspace_mm;
        let half_w = (self.tissue_nodes[0] / 2) as f64 * SPACING_MM;
        let half_h = (self.tissue_nodes[1] / 2) as f64 * SPACING_MM;
        let in_range = |x: f64| x.is_finite() && x.abs() <= 100.0;
        let workspace = (0..3).all(|k| in_range(lo[k]) && in_range(hi[k]) && lo[k] <= hi[k]);
        let sides = (self.grid..=64).contains(&self.tissue_nodes[0])
            && (self.grid..=64).contains(&self.tissue_nodes[1])
            && half_w <= 100.0
            && half_h <= 100.0;
        let friction = self.mu_s.is_finite()
            && self.mu_k.is_finite()
            && 0.0 <= self.mu_k
            && self.mu_k <= self.mu_s
            && self.mu_s <= 2.0;
        if !(workspace && sides && friction) {
            return Err(BoardConfigError::Tissue);
        }
        Ok(())
    }

    /// The encoder's configuration: the plausibility step from the fastest probe speed
    /// at the tick rate (one frame per tick).
    pub fn encoder(&self) -> EncoderConfig {
        EncoderConfig {
            zero: self.encoder_zero,
            mm_per_count: self.mm_per_count,
            max_step: EncoderConfig::max_step_for(
                self.mm_per_count,
                self.max_speed_mm_s,
                self.tick_hz as f64,
            ),
            diag_every: self.diag_every,
            max_travel_counts: libm::ceil(self.travel_mm / libm::fabs(self.mm_per_count))
                .clamp(0.0, (1u32 << 24) as f64) as u32,
        }
    }

    /// The motor's configuration.
    pub fn motor(&self) -> MotorConfig {
        MotorConfig {
            force_at_full_duty: self.force_at_full_duty,
        }
    }

    /// The tick's budget and costs, for the link's tissue check.
    pub fn budget(&self) -> mccs_firmware::link::TickBudget {
        mccs_firmware::link::TickBudget {
            tick: self.tick_budget,
            base: self.tick_base_cost,
            per_substep: self.substep_cost,
        }
    }

    /// The workspace in the link's units (Q24 mm).
    pub fn workspace_q24(&self) -> [[i32; 3]; 2] {
        self.workspace_mm.map(|c| c.map(mccs_link::scale::mm_bits))
    }

    /// The solver's configuration: the board's tick, patch and coupling (the node mass
    /// in kg, as the solver takes it), the rest the solver's defaults.
    pub fn solver(&self) -> SolverConfig {
        SolverConfig {
            tick_hz: self.tick_hz as f64,
            node_mass: self.node_mass_g / 1000.0,
            spring_damping: self.spring_damping,
            coupling: Coupling {
                stiffness: self.coupling_stiffness,
                damping: self.coupling_damping,
                max_force: self.max_force,
            },
            integrator: self.integrator,
            ..SolverConfig::default()
        }
    }
}
