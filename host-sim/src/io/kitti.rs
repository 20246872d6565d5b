//! KITTI Velodyne frames (`velodyne_points/data/*.bin` of the raw data, `velodyne/*.bin` of
//! the odometry benchmark): one HDL-64E revolution per file (docs/frames.md, *KITTI*).
//!
//! - Records of 16 bytes, no header: x, y, z (metres) and reflectance (0–1), each a
//!   little-endian `f32`. The file size must be a multiple of 16.
//! - Frame: the Velodyne's, x ahead, y left, z up, the origin at the sensor (about 1.73 m
//!   above the road on the KITTI car). No conversion is needed.
//! - The ring is not stored. The points are stored laser by laser, and within a laser in
//!   increasing azimuth θ = atan2(y, x) taken in [0°, 360°): each laser starts facing ahead
//!   (θ ≈ 0°), turns through the left (90°), the back (180°) and the right (270°) and ends
//!   ahead again. A new ring therefore starts wherever θ falls back by more than
//!   [`RING_BREAK_DEG`]; within a ring it never decreases by more than float noise.
//!   A file that yields more than [`HDL64_RINGS`] rings is not stored that way and is
//!   refused.

use super::sweep::{f32_at, read_bytes, Sweep, SweepError, SweepFormat};
use std::path::Path;

/// Bytes per point record.
pub const RECORD_LEN: usize = 16;
/// Lasers of the HDL-64E.
pub const HDL64_RINGS: u16 = 64;
/// A backward step of θ larger than this starts a new ring, degrees. Within a ring θ falls
/// back by at most a few thousandths of a degree (float rounding of points at the same
/// azimuth); between two rings it falls back by the span of the first ring's last part and
/// the next one's missing first part, tens to hundreds of degrees.
pub const RING_BREAK_DEG: f32 = 1.0;

/// Reads a KITTI `.bin` frame and recovers each point's ring from the stored order.
pub fn read_kitti(path: &Path) -> Result<Sweep, SweepError> {
    let bytes = read_bytes(path)?;
    parse_kitti(&bytes, path)
}

/// Parses the bytes of a KITTI `.bin` frame (`path` only names it in errors).
pub fn parse_kitti(bytes: &[u8], path: &Path) -> Result<Sweep, SweepError> {
    if bytes.is_empty() {
        return Err(SweepError::format(
            path,
            "empty file: a KITTI frame holds x, y, z, reflectance as float32 records of 16 bytes",
        ));
    }
    if !bytes.len().is_multiple_of(RECORD_LEN) {
        return Err(SweepError::format(
            path,
            format!(
                "size {} bytes is not a multiple of 16 (KITTI records are x, y, z, reflectance as float32); truncated or not a KITTI frame",
                bytes.len()
            ),
        ));
    }
    let n = bytes.len() / RECORD_LEN;
    let mut s = Sweep::with_capacity(SweepFormat::Kitti, n);
    let mut ring: u16 = 0;
    let mut last_theta = f32::NEG_INFINITY;
    for rec in bytes.chunks_exact(RECORD_LEN) {
        let (x, y, z, r) = (
            f32_at(rec, 0),
            f32_at(rec, 1),
            f32_at(rec, 2),
            f32_at(rec, 3),
        );
        if !(x.is_finite() && y.is_finite() && z.is_finite()) {
            s.dropped_non_finite += 1;
            continue;
        }
        let theta = theta_deg(x, y);
        if theta < last_theta - RING_BREAK_DEG {
            ring += 1;
            if ring >= HDL64_RINGS {
                return Err(SweepError::format(
                    path,
                    format!(
                        "azimuth falls back more than {} times: the points are not stored laser by laser as KITTI frames are, so rings cannot be recovered",
                        HDL64_RINGS - 1
                    ),
                ));
            }
        }
        last_theta = theta;
        s.push(x, y, z, r, ring);
    }
    if s.is_empty() {
        return Err(SweepError::format(path, "no point with finite coordinates"));
    }
    s.rings = HDL64_RINGS;
    Ok(s)
}

/// Azimuth θ = atan2(y, x) in degrees, in [0°, 360°): 0° ahead, 90° left.
#[inline]
pub fn theta_deg(x: f32, y: f32) -> f32 {
    let a = y.atan2(x).to_degrees();
    if a < 0.0 {
        a + 360.0
    } else {
        a
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(p: [f32; 4]) -> Vec<u8> {
        p.iter().flat_map(|v| v.to_le_bytes()).collect()
    }

    /// Three lasers, each a full turn from ahead through the left, the back and the right;
    /// the second misses its first quarter (no return ahead-left), the third its last.
    fn three_rings() -> Vec<u8> {
        let mut b = Vec::new();
        for (k, (from, to)) in [(0.0f32, 359.0f32), (95.0, 359.5), (0.5, 270.0)]
            .into_iter()
            .enumerate()
        {
            let r = 5.0 + k as f32;
            let mut a = from;
            while a <= to {
                let t = a.to_radians();
                b.extend(record([r * t.cos(), r * t.sin(), -1.7, 0.1 * k as f32]));
                a += 0.5;
            }
        }
        b
    }

    #[test]
    fn rings_follow_the_azimuth_falling_back() {
        let s = parse_kitti(&three_rings(), Path::new("t.bin")).unwrap();
        assert_eq!(s.rings, 64);
        let mut counts = [0usize; 3];
        for (i, &r) in s.ring.iter().enumerate() {
            counts[usize::from(r)] += 1;
            // The ring recovered is the laser the test wrote (its range tells it).
            let range = s.x[i].hypot(s.y[i]);
            assert!((range - (5.0 + f32::from(r))).abs() < 1e-3, "point {i}");
        }
        assert_eq!(counts, [719, 530, 540]);
        assert_eq!(s.format, SweepFormat::Kitti);
        assert!((s.z[0] + 1.7).abs() < 1e-6 && s.intensity[719] == 0.1);
    }

    #[test]
    fn non_finite_points_are_counted_not_kept() {
        let mut b = three_rings();
        b.extend(record([f32::NAN, 1.0, 1.0, 0.0]));
        let s = parse_kitti(&b, Path::new("t.bin")).unwrap();
        assert_eq!((s.len(), s.dropped_non_finite), (1789, 1));
    }

    #[test]
    fn bad_files_are_refused_in_one_sentence_naming_the_file() {
        let e = parse_kitti(&[0u8; 17], Path::new("a/b.bin"))
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("a/b.bin: size 17 bytes is not a multiple of 16"),
            "{e}"
        );
        let e = parse_kitti(&[], Path::new("e.bin"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("e.bin: empty file"), "{e}");
        // Points in random azimuth order (not stored laser by laser).
        let mut b = Vec::new();
        for k in 0..2000u32 {
            let a = ((k * 97) % 360) as f32;
            b.extend(record([
                a.to_radians().cos(),
                a.to_radians().sin(),
                0.0,
                0.0,
            ]));
        }
        let e = parse_kitti(&b, Path::new("s.bin")).unwrap_err().to_string();
        assert!(e.contains("not stored laser by laser"), "{e}");
        let e = read_kitti(Path::new("/nonexistent/f.bin"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("/nonexistent/f.bin: "), "{e}");
    }
}
