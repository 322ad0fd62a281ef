//! The link's byte budget: how much a baud rate carries, what a frame of each streamed
//! message takes at most, and so how often the device may send them (docs/link.md,
//! "The link's bytes"). The device holds `Watch` and `WatchMesh` to these; its hello
//! tells a scene the rates.

/// The link's default baud rate: 1,000,000, exact on the STM32F405's USART2 at APB1
/// 42 MHz (oversampling by 16: 42 MHz / 16 / 2.625), and carried by common USB-serial
/// bridges (FT232R, CP2102N, CH340).
pub const DEFAULT_BAUD: u32 = 1_000_000;

/// Bytes a second at `baud`, 8N1 (ten bits a byte).
pub const fn bytes_per_second(baud: u32) -> u32 {
    baud / 10
}

/// The share of the device's bytes a second that telemetry may take, percent.
pub const TELEMETRY_SHARE_PCT: u32 = 40;
/// The share meshes may take, percent. The rest (20 %) is for answers, replay rows
/// and margin.
pub const MESH_SHARE_PCT: u32 = 40;

/// The largest telemetry frame, bytes (delimiter included): every field at its longest
/// varint (a test encodes that message and holds it here).
pub const TELEMETRY_FRAME_MAX: u32 = 99;
/// The largest mesh part's frame, bytes.
pub const MESH_PART_FRAME_MAX: u32 = 237;

/// How long a host may stay silent while it holds the device armed, ms: past it the
/// force fades to zero and the device disarms.
pub const SILENCE_TIMEOUT_MS: u32 = 100;
/// How long the fade lasts, ms.
pub const FADE_MS: u32 = 20;
/// How long a replay waits for its path's next sample, ms: past it the device abandons
/// the replay (`ReplayEnd` with the ticks it ran), so that a host that stopped feeding
/// it (gone, or given up) does not hold the device's one job, and every load, for good.
pub const REPLAY_STARVED_MS: u32 = 1000;
/// How often an armed host with nothing else to say sends a frame (a `Keepalive`), ms:
/// four to a timeout.
pub const KEEPALIVE_MS: u32 = 25;

/// The fewest ticks between two messages of `frame_bytes` each that `share_pct` of the
/// bytes `baud` carries allows at `tick_hz` (at least 1).
pub const fn least_every(tick_hz: u32, baud: u32, frame_bytes: u32, share_pct: u32) -> u16 {
    let budget = bytes_per_second(baud) as u64 * share_pct as u64;
    if budget == 0 {
        return u16::MAX;
    }
    let every = (tick_hz as u64 * frame_bytes as u64 * 100).div_ceil(budget);
    if every > u16::MAX as u64 {
        u16::MAX
    } else if every == 0 {
        1
    } else {
        every as u16
    }
}

/// The fewest ticks between two telemetry messages.
pub const fn telemetry_least_every(tick_hz: u32, baud: u32) -> u16 {
    least_every(tick_hz, baud, TELEMETRY_FRAME_MAX, TELEMETRY_SHARE_PCT)
}

/// The fewest ticks between two meshes of `nodes` nodes.
pub const fn mesh_least_every(tick_hz: u32, baud: u32, nodes: usize) -> u16 {
    let parts = nodes.div_ceil(crate::info::MESH_PART) as u32;
    least_every(tick_hz, baud, parts * MESH_PART_FRAME_MAX, MESH_SHARE_PCT)
}
