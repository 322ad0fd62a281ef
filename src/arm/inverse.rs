//! The arm's inverse kinematics in `f64` (start-up and host only; never in the tick):
//! the joint angles that put the probe at a point of the device frame, on the arm's
//! working branch. Written once for every user: the simulated arms of the firmware (the
//! demo's and the board's plant) and the host's twin.
//!
//! Of the solutions — the base's yaw toward the point or away from it with the reach
//! negated, each with the elbow on either side of the line from the shoulder to the
//! probe — the one with the elbow bent forward (`0 < B + C < 180°`), every joint within
//! its range (to [`RANGE_SLACK_DEG`]), nearest the home pose in the sum of the angles' distances; `None` when no
//! solution is on that branch within the ranges, or the point is out of reach.

use super::spec::ArmSpec;

/// How far past a joint's range a solution may be, degrees: a point the arm reached at
/// its limit, read back through the fixed-point kinematics (within 10 µm), lands a few
/// thousandths of a degree from it.
pub const RANGE_SLACK_DEG: f64 = 0.02;

/// Joint angles A, B, C (rad) that put the probe at `device_mm` (the device frame: on
/// the base's axis, `z` up, mm), or `None` (see the module docs).
pub fn angles(spec: &ArmSpec, device_mm: [f64; 3]) -> Option<[f64; 3]> {
    let (lb, lc) = (spec.upper_arm_mm, spec.forearm_mm);
    let [x, y, z] = device_mm;
    let h = z - spec.base_height_mm;
    let reach = libm::hypot(x, y);
    let home: [f64; 3] = core::array::from_fn(|k| spec.joints[k].home_angle_deg.to_radians());
    let within = |t: &[f64; 3]| {
        (0..3).all(|k| {
            let j = &spec.joints[k];
            let d = t[k].to_degrees();
            d >= j.min_angle_deg - RANGE_SLACK_DEG && d <= j.max_angle_deg + RANGE_SLACK_DEG
        })
    };
    let mut best: Option<([f64; 3], f64)> = None;
    for (a, r) in [(libm::atan2(y, x), reach), (libm::atan2(-y, -x), -reach)] {
        let d2 = r * r + h * h;
        let d = libm::sqrt(d2);
        if !(d < lb + lc && d > (lb - lc).abs()) {
            continue;
        }
        // The elbow: on the circle of radius Lb about the shoulder and Lc about the tip,
        // `along` from the shoulder toward the probe and `off` to either side.
        let along = (lb * lb - lc * lc + d2) / (2.0 * d);
        let off = libm::sqrt((lb * lb - along * along).max(0.0));
        let (ur, uh) = (r / d, h / d);
        for side in [1.0, -1.0] {
            let (er, eh) = (along * ur - side * off * uh, along * uh + side * off * ur);
            // B from vertical up to the elbow; C from vertical down, elbow to probe.
            let t = [a, libm::atan2(er, eh), libm::atan2(r - er, -(h - eh))];
            if libm::sin(t[1] + t[2]) <= 0.0 || !within(&t) {
                continue;
            }
            let dist: f64 = (0..3).map(|k| (t[k] - home[k]).abs()).sum();
            if best.is_none_or(|(_, b)| dist < b) {
                best = Some((t, dist));
            }
        }
    }
    best.map(|(t, _)| t)
}

/// The joint counts of `angles` (rad), to the nearest count: the convention's inverse
/// (`count = home_count + (θ − home_angle) · counts_per_rev · ratio / (2π · sign)`).
pub fn counts_of(spec: &ArmSpec, angles: [f64; 3]) -> [i32; 3] {
    core::array::from_fn(|k| {
        let j = &spec.joints[k];
        let per_turn = j.counts_per_rev * j.ratio;
        let turns = (angles[k] - j.home_angle_deg.to_radians()) / core::f64::consts::TAU;
        libm::round(j.home_count as f64 + turns * per_turn / j.sign) as i32
    })
}

/// The joint counts that put the probe at `device_mm`, or `None` ([`angles`]).
pub fn counts(spec: &ArmSpec, device_mm: [f64; 3]) -> Option<[i32; 3]> {
    angles(spec, device_mm).map(|t| counts_of(spec, t))
}
