//! nuScenes lidar sweeps (`samples/LIDAR_TOP/*.pcd.bin`, `sweeps/LIDAR_TOP/*.pcd.bin`): one
//! HDL-32E revolution at 20 Hz per file (docs/frames.md, *nuScenes*).
//!
//! - Despite the name, not PCD: records of 20 bytes, no header: x, y, z (metres),
//!   intensity (0–255) and ring (0–31, as a float), each a little-endian `f32`.
//! - nuScenes' `LIDAR_TOP` frame has **x to the right, y ahead**, z up. The reader turns it
//!   into the product's sensor frame (x ahead, y left): x = y_nuScenes, y = −x_nuScenes.
//! - Ring 0 is the lowest laser (−30.7°), ring 31 the highest (+10.7°).
//! - The HDL-32E reports a missed return as a point about 0.45 m from the origin; those
//!   are kept here and dropped, like every point inside the vehicle, by the ring assembly's
//!   minimum range.

use super::sweep::{f32_at, read_bytes, Sweep, SweepError, SweepFormat};
use std::path::Path;

/// Bytes per point record.
pub const RECORD_LEN: usize = 20;
/// Lasers of the HDL-32E.
pub const HDL32_RINGS: u16 = 32;

/// Reads a nuScenes `.pcd.bin` sweep.
pub fn read_nuscenes(path: &Path) -> Result<Sweep, SweepError> {
    let bytes = read_bytes(path)?;
    parse_nuscenes(&bytes, path)
}

/// Parses the bytes of a nuScenes `.pcd.bin` sweep (`path` only names it in errors).
pub fn parse_nuscenes(bytes: &[u8], path: &Path) -> Result<Sweep, SweepError> {
    if bytes.is_empty() {
        return Err(SweepError::format(path, "empty file: a nuScenes sweep holds x, y, z, intensity, ring as float32 records of 20 bytes"));
    }
    if !bytes.len().is_multiple_of(RECORD_LEN) {
        let hint = if bytes.len().is_multiple_of(16) {
            " (a multiple of 16: a KITTI frame? use --format kitti)"
        } else {
            ""
        };
        return Err(SweepError::format(
            path,
            format!(
                "size {} bytes is not a multiple of 20 (nuScenes records are x, y, z, intensity, ring as float32){hint}",
                bytes.len()
            ),
        ));
    }
    let n = bytes.len() / RECORD_LEN;
    let mut s = Sweep::with_capacity(SweepFormat::NuScenes, n);
    for (i, rec) in bytes.chunks_exact(RECORD_LEN).enumerate() {
        let ring = f32_at(rec, 4);
        if !(ring >= 0.0 && ring < f32::from(HDL32_RINGS) && ring.fract() == 0.0) {
            return Err(SweepError::format(
                path,
                format!("point {i} has ring {ring}, not a whole number in 0..=31 (HDL-32E)"),
            ));
        }
        let (xn, yn) = (f32_at(rec, 0), f32_at(rec, 1));
        s.push(yn, -xn, f32_at(rec, 2), f32_at(rec, 3), ring as u16);
    }
    s.rings = HDL32_RINGS;
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(p: [f32; 5]) -> Vec<u8> {
        p.iter().flat_map(|v| v.to_le_bytes()).collect()
    }

    #[test]
    fn axes_are_turned_to_x_ahead_y_left() {
        // A point 10 m ahead of the car is at y = +10 in nuScenes' frame; one 3 m to the
        // left at x = −3.
        let mut b = record([0.0, 10.0, -1.8, 7.0, 4.0]);
        b.extend(record([-3.0, 0.0, -1.8, 9.0, 31.0]));
        let s = parse_nuscenes(&b, Path::new("n.pcd.bin")).unwrap();
        assert_eq!((s.x[0], s.y[0], s.z[0]), (10.0, 0.0, -1.8));
        assert_eq!((s.x[1], s.y[1]), (0.0, 3.0));
        assert_eq!((s.ring.as_slice(), s.rings), ([4u16, 31].as_slice(), 32));
        assert_eq!(s.intensity, vec![7.0, 9.0]);
    }

    #[test]
    fn bad_files_are_refused_in_one_sentence_naming_the_file() {
        let e = parse_nuscenes(&[0u8; 32], Path::new("k.bin"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("not a multiple of 20") && e.contains("KITTI"),
            "{e}"
        );
        let e = parse_nuscenes(&record([1.0, 2.0, 3.0, 4.0, 32.0]), Path::new("r.bin"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("r.bin: point 0 has ring 32"), "{e}");
        let e = parse_nuscenes(&record([1.0, 2.0, 3.0, 4.0, 2.5]), Path::new("r.bin"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("ring 2.5"), "{e}");
    }
}
