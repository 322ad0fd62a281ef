//! A pose as text: the comma-separated numbers a command line or a page sends
//! (`X,Y,Z` mm, `RX,RY,RZ` degrees), each finite.

use mccs_link::Pose;

/// `K` comma-separated finite numbers (spaces round each allowed), or `None`.
pub fn numbers<const K: usize>(text: &str) -> Option<[f64; K]> {
    let mut out = [0.0; K];
    let mut parts = text.split(',');
    for slot in out.iter_mut() {
        *slot = parts
            .next()?
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())?;
    }
    parts.next().is_none().then_some(out)
}

/// `X,Y,Z,RX,RY,RZ`: the tissue's origin in mm and its rotation in degrees.
pub fn pose(text: &str) -> Option<Pose> {
    let [x, y, z, rx, ry, rz] = numbers::<6>(text)?;
    Some(Pose::from_mm_deg([x, y, z], [rx, ry, rz]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exactly_k_finite_numbers() {
        assert_eq!(numbers::<3>(" 1, 2.5 ,-3"), Some([1.0, 2.5, -3.0]));
        for bad in ["1,2", "1,2,3,4", "1,,3", "1,2,nan", "1,2,inf", "a,b,c", ""] {
            assert_eq!(numbers::<3>(bad), None, "{bad:?}");
        }
        assert!(pose("1,2,3,0,0,90").is_some());
        assert!(pose("1,2,3").is_none());
    }
}
