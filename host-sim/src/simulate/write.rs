//! Writers: `points.laz` (LAS 1.4, point format 6, 1 mm scale, CRS offsets, WKT CRS VLR)
//! and `trajectory.csv` (docs/spec.md §3).

use super::scanner::Return;
use super::SimError;
use crate::io::trajectory::Trajectory;
use crate::model::{Crs, EdgeLine};
use std::io::Write;
use std::path::Path;

/// LAS scan angle unit, degrees.
const SCAN_ANGLE_UNIT: f64 = 0.006;

/// WKT of the CRS for the EPSG codes the scenes use.
pub fn wkt_for(epsg: u32) -> Option<String> {
    let zone_cm = match epsg {
        6691 => (54, 141),
        6690 => (53, 135),
        6692 => (55, 147),
        _ => return None,
    };
    Some(format!(
        "PROJCS[\"JGD2011 / UTM zone {z}N\",GEOGCS[\"JGD2011\",DATUM[\"Japanese_Geodetic_Datum_2011\",\
SPHEROID[\"GRS 1980\",6378137,298.257222101,AUTHORITY[\"EPSG\",\"7019\"]],AUTHORITY[\"EPSG\",\"1128\"]],\
PRIMEM[\"Greenwich\",0,AUTHORITY[\"EPSG\",\"8901\"]],UNIT[\"degree\",0.0174532925199433,AUTHORITY[\"EPSG\",\"9122\"]],\
AUTHORITY[\"EPSG\",\"6668\"]],PROJECTION[\"Transverse_Mercator\"],PARAMETER[\"latitude_of_origin\",0],\
PARAMETER[\"central_meridian\",{cm}],PARAMETER[\"scale_factor\",0.9996],PARAMETER[\"false_easting\",500000],\
PARAMETER[\"false_northing\",0],UNIT[\"metre\",1,AUTHORITY[\"EPSG\",\"9001\"]],AXIS[\"Easting\",EAST],\
AXIS[\"Northing\",NORTH],AUTHORITY[\"EPSG\",\"{epsg}\"]]",
        z = zone_cm.0,
        cm = zone_cm.1
    ))
}

/// The value to hand to `las` so that its truncating conversion
/// (`(deg / 0.006) as i16`) yields the *rounded* count: half a unit further from zero.
pub fn scan_angle_for_las(deg: f64) -> f32 {
    let n = (deg / SCAN_ANGLE_UNIT).round().clamp(-30000.0, 30000.0);
    let nudged = if n == 0.0 { 0.0 } else { n + 0.5 * n.signum() };
    (nudged * SCAN_ANGLE_UNIT) as f32
}

/// Writes the returns (scene-local + `origin`) as LAS 1.4 format 6; LAZ when the path ends
/// in `.laz`.
pub fn write_points(
    path: &Path,
    returns: &[Return],
    origin: [f64; 3],
    epsg: u32,
) -> Result<(), SimError> {
    write_points_with(path, returns, origin, epsg, None)
}

/// The Extra Bytes VLR (LAS 1.4 R15 §2.5.7.2) describing one `u16` dimension named `name`.
pub fn ring_vlr(name: &str) -> las::Vlr {
    let mut d = vec![0u8; 192];
    d[2] = 3; // data type: unsigned short
    let n = name.as_bytes();
    d[4..4 + n.len().min(32)].copy_from_slice(&n[..n.len().min(32)]);
    let desc = b"laser ring, 0 = lowest beam";
    d[160..160 + desc.len()].copy_from_slice(desc);
    las::Vlr {
        user_id: "LASF_Spec".into(),
        record_id: 4,
        description: "Extra Bytes".into(),
        data: d,
    }
}

/// [`write_points`], with each return's ring as a `u16` extra-bytes dimension named
/// `ring_name` when given.
pub fn write_points_with(
    path: &Path,
    returns: &[Return],
    origin: [f64; 3],
    epsg: u32,
    ring_name: Option<&str>,
) -> Result<(), SimError> {
    write_points_channels(path, returns, None, origin, epsg, ring_name)
}

/// [`write_points_with`], with return `i`'s scanner channel `channels[i]` (and point
/// source id `channels[i] + 1`) when given; channel 0 and point source id 1 otherwise.
pub fn write_points_channels(
    path: &Path,
    returns: &[Return],
    channels: Option<&[u8]>,
    origin: [f64; 3],
    epsg: u32,
    ring_name: Option<&str>,
) -> Result<(), SimError> {
    let err = |e: las::Error| SimError::Write {
        path: path.display().to_string(),
        what: e.to_string(),
    };
    let mut b = las::Builder::from(las::Version::new(1, 4));
    b.point_format = las::point::Format::new(6).map_err(err)?;
    if let Some(name) = ring_name {
        b.point_format.extra_bytes = 2;
        b.vlrs.push(ring_vlr(name));
    }
    b.generating_software = "curbtrace simulate".into();
    b.system_identifier = "curbtrace scene simulator".into();
    b.gps_time_type = las::GpsTimeType::Standard;
    // Offsets: the scene origin rounded to whole metres, scale 1 mm.
    b.transforms = las::Vector {
        x: las::Transform {
            scale: 0.001,
            offset: origin[0].floor(),
        },
        y: las::Transform {
            scale: 0.001,
            offset: origin[1].floor(),
        },
        z: las::Transform {
            scale: 0.001,
            offset: 0.0,
        },
    };
    let mut header = b.into_header().map_err(err)?;
    if let Some(wkt) = wkt_for(epsg) {
        header.set_wkt_crs(wkt.into_bytes()).map_err(err)?;
    }
    let mut w = las::Writer::from_path(path, header).map_err(err)?;
    let wheader = w.header().clone();
    let builder = || las::PointDataBuilder::new().for_header(&wheader);
    let channel = |i: usize| channels.and_then(|c| c.get(i)).copied().unwrap_or(0);
    let to_point = |(i, r): (usize, &Return)| las::Point {
        x: r.p[0] + origin[0],
        y: r.p[1] + origin[1],
        z: r.p[2] + origin[2],
        intensity: r.intensity,
        return_number: 1,
        number_of_returns: 1,
        scanner_channel: channel(i),
        scan_angle: scan_angle_for_las(r.scan_angle_deg),
        point_source_id: u16::from(channel(i)) + 1,
        gps_time: Some(r.t),
        extra_bytes: if ring_name.is_some() {
            r.ring.to_le_bytes().to_vec()
        } else {
            Vec::new()
        },
        ..Default::default()
    };
    // Slabs of a million points: the LAZ writer compresses a slab's chunks in parallel.
    for (k, chunk) in returns.chunks(1 << 20).enumerate() {
        let pd = builder()
            .build_from_points(
                (0..chunk.len())
                    .map(|i| (k << 20) + i)
                    .zip(chunk)
                    .map(to_point),
            )
            .map_err(err)?;
        w.write_points(&pd).map_err(err)?;
    }
    w.close().map_err(err)?;
    Ok(())
}

/// The CRS of a simulation's outputs: the same text as the LAS file's WKT VLR, so that
/// readers deriving the CRS from the points and from a reference get identical values.
pub fn crs_for(epsg: u32) -> Crs {
    wkt_for(epsg).map(Crs::Wkt).unwrap_or(Crs::Epsg(epsg))
}

/// Writes reference lines to `path` as GeoJSON in `crs`.
pub fn write_reference(path: &Path, lines: &[EdgeLine], crs: &Crs) -> Result<(), SimError> {
    crate::output::geojson::write_geojson(path, lines, Some(crs)).map_err(|e| SimError::Write {
        path: path.display().to_string(),
        what: e.to_string(),
    })
}

/// Writes `time,x,y,z,roll,pitch,heading` (docs/spec.md §3), positions + `origin`.
pub fn write_trajectory(path: &Path, traj: &Trajectory, origin: [f64; 3]) -> Result<(), SimError> {
    let io = |source: std::io::Error| SimError::Io {
        path: path.display().to_string(),
        source,
    };
    let f = std::fs::File::create(path).map_err(io)?;
    let mut w = std::io::BufWriter::new(f);
    writeln!(w, "time,x,y,z,roll,pitch,heading").map_err(io)?;
    for s in &traj.samples {
        writeln!(
            w,
            "{:.6},{:.4},{:.4},{:.4},{:.5},{:.5},{:.5}",
            s.t,
            s.x + origin[0],
            s.y + origin[1],
            s.z + origin[2],
            s.roll_deg,
            s.pitch_deg,
            s.heading_deg
        )
        .map_err(io)?;
    }
    w.flush().map_err(io)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scan_angle_survives_the_las_truncation_rounded() {
        // 0.0179 / 0.006 = 2.98: rounding gives 3 units; plain truncation would give 2.
        for (deg, units) in [
            (0.0179, 3i16),
            (-0.0179, -3),
            (0.0, 0),
            (179.91, 29985),
            (-180.0, -30000),
            (0.002, 0),
        ] {
            let v = scan_angle_for_las(deg);
            let got = las::raw::point::ScanAngle::from(v);
            assert_eq!(i16::from(got), units, "{deg}");
        }
    }
}
