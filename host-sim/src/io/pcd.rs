//! PCD files (Point Cloud Library, versions 0.5–0.7; `DATA ascii`, `binary` and
//! `binary_compressed`) with a ring field, as ROS drivers of spinning lidars write them
//! (docs/frames.md, *PCD*). Parsing is the `pcd-rs` crate's; this module picks the fields.
//!
//! - Required fields: `x`, `y`, `z` and a ring: `ring` (Velodyne, Hesai), `laser_id` or
//!   `channel` (Ouster, some Livox/Robosense exports), the first of these names found; any
//!   numeric type, one value each (`COUNT 1`). A ring must be a whole number in 0..65535.
//! - Optional: `intensity` (or `reflectivity`), else 0.
//! - Frame: as the file says, which for ROS drivers is REP 103's x ahead, y left, z up, the
//!   origin at the sensor; the reader does not move or turn points. `VIEWPOINT` is ignored.
//! - A file without a ring field is refused: the scanline rule needs the ring, and
//!   guessing it from an organized cloud's rows is not done.

use super::sweep::{Sweep, SweepError, SweepFormat};
use pcd_rs::{DynReader, DynRecord, Field};
use std::path::Path;

/// Names accepted for the ring field, in order of preference.
pub const RING_FIELDS: [&str; 3] = ["ring", "laser_id", "channel"];
/// Names accepted for the intensity field, in order of preference.
pub const INTENSITY_FIELDS: [&str; 2] = ["intensity", "reflectivity"];

/// Reads a PCD file with a ring field.
pub fn read_pcd(path: &Path) -> Result<Sweep, SweepError> {
    if let Err(e) = std::fs::metadata(path) {
        return Err(SweepError::io(path, e));
    }
    let reader = DynReader::open(path)
        .map_err(|e| SweepError::format(path, format!("not a readable PCD file: {e}")))?;
    let meta = reader.meta().clone();
    let names: Vec<&str> = meta.field_defs.iter().map(|f| f.name.as_str()).collect();
    let find = |cands: &[&str]| cands.iter().find_map(|c| names.iter().position(|n| n == c));
    let (Some(ix), Some(iy), Some(iz)) = (find(&["x"]), find(&["y"]), find(&["z"])) else {
        return Err(SweepError::format(
            path,
            format!("needs fields x, y and z; it has {}", names.join(" ")),
        ));
    };
    let Some(ir) = find(&RING_FIELDS) else {
        return Err(SweepError::format(
            path,
            format!(
                "has no ring field (one of {}; fields: {}): the ring of every point is needed to cut scanlines",
                RING_FIELDS.join(", "),
                names.join(" ")
            ),
        ));
    };
    let ii = find(&INTENSITY_FIELDS);
    for (i, name) in [
        (Some(ix), "x"),
        (Some(iy), "y"),
        (Some(iz), "z"),
        (Some(ir), names[ir]),
        (ii, "intensity"),
    ] {
        if let Some(k) = i.filter(|&k| meta.field_defs.fields[k].count != 1) {
            return Err(SweepError::format(
                path,
                format!(
                    "field {name} has COUNT {}, not 1",
                    meta.field_defs.fields[k].count
                ),
            ));
        }
    }
    let mut s = Sweep::with_capacity(SweepFormat::Pcd, meta.num_points as usize);
    for (i, rec) in reader.enumerate() {
        let rec: DynRecord =
            rec.map_err(|e| SweepError::format(path, format!("point {i} could not be read: {e}")))?;
        let v = |k: usize| rec.0.get(k).and_then(scalar);
        let (Some(x), Some(y), Some(z), Some(r)) = (v(ix), v(iy), v(iz), v(ir)) else {
            return Err(SweepError::format(
                path,
                format!("point {i} has fewer fields than the header"),
            ));
        };
        if !(r >= 0.0 && r < f64::from(u16::MAX) && r.fract() == 0.0) {
            return Err(SweepError::format(
                path,
                format!(
                    "point {i} has {} {r}, not a whole number in 0..65535",
                    names[ir]
                ),
            ));
        }
        let intensity = ii.and_then(v).unwrap_or(0.0);
        s.push(x as f32, y as f32, z as f32, intensity as f32, r as u16);
    }
    if s.len() as u64 + s.dropped_non_finite != meta.num_points {
        return Err(SweepError::format(
            path,
            format!(
                "the header says {} points, the data holds {}",
                meta.num_points,
                s.len() as u64 + s.dropped_non_finite
            ),
        ));
    }
    Ok(s)
}

/// The first value of a field as `f64`.
fn scalar(f: &Field) -> Option<f64> {
    Some(match f {
        Field::I8(v) => f64::from(*v.first()?),
        Field::I16(v) => f64::from(*v.first()?),
        Field::I32(v) => f64::from(*v.first()?),
        Field::I64(v) => *v.first()? as f64,
        Field::U8(v) => f64::from(*v.first()?),
        Field::U16(v) => f64::from(*v.first()?),
        Field::U32(v) => f64::from(*v.first()?),
        Field::U64(v) => *v.first()? as f64,
        Field::F32(v) => f64::from(*v.first()?),
        Field::F64(v) => *v.first()?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use pcd_rs::{DataKind, DynWriter, Schema, ValueKind, WriterInit};

    /// Writes a PCD of `n` points with pcd-rs' own writer: x, y, z as f32, intensity as
    /// u8 and `ring_name` as u16.
    fn write(path: &Path, kind: DataKind, ring_name: &str, n: usize) {
        let schema = Schema::from_iter([
            ("x", ValueKind::F32, 1),
            ("y", ValueKind::F32, 1),
            ("z", ValueKind::F32, 1),
            ("intensity", ValueKind::U8, 1),
            (ring_name, ValueKind::U16, 1),
        ]);
        let mut w: DynWriter<_> = WriterInit {
            width: n as u64,
            height: 1,
            viewpoint: Default::default(),
            data_kind: kind,
            schema: Some(schema),
            version: None,
        }
        .create(path)
        .unwrap();
        for i in 0..n {
            w.push(&DynRecord(vec![
                Field::F32(vec![i as f32 * 0.5]),
                Field::F32(vec![-(i as f32)]),
                Field::F32(vec![-1.5]),
                Field::U8(vec![(i % 256) as u8]),
                Field::U16(vec![(i % 16) as u16]),
            ]))
            .unwrap();
        }
        w.finish().unwrap();
    }

    #[test]
    fn ascii_binary_and_compressed_read_the_same() {
        let dir = tempfile::tempdir().unwrap();
        let mut sweeps = Vec::new();
        for (k, kind) in [
            DataKind::Ascii,
            DataKind::Binary,
            DataKind::BinaryCompressed,
        ]
        .into_iter()
        .enumerate()
        {
            let p = dir.path().join(format!("f{k}.pcd"));
            write(&p, kind, "ring", 40);
            let s = read_pcd(&p).unwrap();
            assert_eq!(s.len(), 40);
            assert_eq!((s.x[3], s.y[3], s.z[3]), (1.5, -3.0, -1.5));
            assert_eq!((s.ring[17], s.intensity[17], s.rings), (1, 17.0, 16));
            assert_eq!(s.format, SweepFormat::Pcd);
            sweeps.push(s);
        }
        assert_eq!(sweeps[0], sweeps[1]);
        assert_eq!(sweeps[1], sweeps[2]);
    }

    #[test]
    fn other_ring_names_are_taken() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("o.pcd");
        write(&p, DataKind::Binary, "laser_id", 20);
        assert_eq!(read_pcd(&p).unwrap().ring[19], 3);
    }

    #[test]
    fn files_without_ring_or_unreadable_are_refused_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("n.pcd");
        write(&p, DataKind::Ascii, "label", 5);
        let e = read_pcd(&p).unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("{}: has no ring field", p.display())),
            "{e}"
        );
        assert!(e.contains("x y z intensity label"), "{e}");
        let q = dir.path().join("junk.pcd");
        std::fs::write(&q, b"hello\n").unwrap();
        let e = read_pcd(&q).unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("{}: not a readable PCD file", q.display())),
            "{e}"
        );
        let e = read_pcd(&dir.path().join("missing.pcd"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing.pcd: "), "{e}");
        // A ring that is not a whole number.
        let r = dir.path().join("r.pcd");
        std::fs::write(
            &r,
            "VERSION .7\nFIELDS x y z ring\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 1\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA ascii\n1 2 3 4.5\n",
        )
        .unwrap();
        let e = read_pcd(&r).unwrap_err().to_string();
        assert!(e.contains("point 0 has ring 4.5"), "{e}");
    }
}
