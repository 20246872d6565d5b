//! LAS/LAZ input as columns (docs/spec.md §3): every point format with GPS time (1, 3, 4,
//! 5, 6–10), any scale and offset, points in any order (sorted by time, stably), one
//! scanner selected, and the file's CRS kept for the output.
//!
//! One subject per file, in the order a file is read:
//!
//! - [`header`]: the fixed header through `las::raw::Header` and its checks against the
//!   file's size;
//! - [`vlrs`]: the variable-length records, and the bounds of the extended ones;
//! - [`laz`]: the `laszip encoded` VLR and the chunk table;
//! - [`crs`]: the CRS from the VLRs;
//! - [`decode`]: the point records, batch by batch, through the `las` crate's byte slab;
//! - [`scanner`]: which points are one scanner;
//! - [`columns`]: the columns the points land in; [`sort`]: their time order.
//!
//! # Memory
//!
//! Columns take 39 B per selected point (see [`PointColumns`]). For uncompressed LAS the
//! header's point count is checked against the file size before anything is allocated, so
//! the columns are reserved once at their final size. For LAZ the count cannot be checked
//! that way; the reservation is capped by the compressed size (see [`laz_reserve_cap`]) and
//! the columns grow only with points actually decoded. Sorting, when needed, holds a `u32`
//! permutation and one temporary column (12 B per point) on top.

mod columns;
mod crs;
mod decode;
mod error;
mod header;
mod laz;
mod scanner;
mod sort;
mod vlrs;

pub use columns::PointColumns;
pub use crs::NoCrs;
pub use decode::CHUNK_POINTS;
pub use error::LasError;
pub use header::format_has_gps_time;
pub use laz::laz_reserve_cap;
pub use scanner::ScannerSelection;

use crate::model::Crs;
use std::fs::File;
use std::path::{Path, PathBuf};

/// The largest number of points one file may hand to the core: the wire's tag is the `u32`
/// index into the columns and `u32::MAX` means "not processed" downstream.
pub const MAX_POINTS: u64 = u32::MAX as u64 - 1;

/// Which scanner to read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ReadOptions {
    /// `--scanner ID`: the scanner channel (formats 6–10 with channels in use) or the point
    /// source id (see [`scanner`]); `None` reads every point.
    pub scanner: Option<u16>,
}

/// What the file's header says, kept beside the columns.
#[derive(Clone, Debug, PartialEq)]
pub struct LasInfo {
    /// The file.
    pub path: PathBuf,
    /// LAS version `(major, minor)`.
    pub version: (u8, u8),
    /// Point data record format (0–10).
    pub point_format: u8,
    /// LAZ-compressed.
    pub compressed: bool,
    /// Points in the file (header count).
    pub points_in_file: u64,
    /// Points kept after scanner selection (the columns' length).
    pub points_selected: u64,
    /// How the points were selected.
    pub selection: ScannerSelection,
    /// The file's CRS: EPSG from the GeoTIFF keys, or the WKT VLR; `None` when absent.
    pub crs: Option<Crs>,
    /// Why `crs` is `None`.
    pub no_crs: Option<NoCrs>,
    /// Whether the points had to be reordered by time.
    pub was_reordered: bool,
    /// Whether the scan angle column carries information (not all one value).
    pub has_scan_angle: bool,
}

/// What [`check_file`] learnt from a file whose header, VLRs and (LAZ) chunk table passed
/// every check.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CheckedHead {
    /// LAS version `(major, minor)`.
    pub version: (u8, u8),
    /// Point data record format (0–10).
    pub format: u8,
    /// LAZ-compressed.
    pub compressed: bool,
    /// Points the header announces.
    pub count: u64,
    /// Points to reserve columns for (see [`laz_reserve_cap`]).
    pub reserve: u64,
    /// Bytes of the file.
    pub file_bytes: u64,
}

/// Checks a file before the `las` crate reads it (see [`check_open_file`]): every reader of
/// point files calls this first.
pub fn check_file(path: &Path) -> Result<CheckedHead, LasError> {
    let io = |source| LasError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut file = File::open(path).map_err(io)?;
    let file_size = file.metadata().map_err(io)?.len();
    let c = check_open_file(path, &mut file, file_size)?;
    Ok(CheckedHead {
        version: c.head.version,
        format: c.head.format,
        compressed: c.head.compressed,
        count: c.head.count,
        reserve: c.reserve,
        file_bytes: file_size,
    })
}

/// The file's CRS, or why it has none.
pub fn header_crs(header: &las::Header) -> Result<Crs, NoCrs> {
    crs::header_crs(header)
}

/// A file whose header, VLRs and (LAZ) chunk table passed every check: the points can be
/// decoded.
struct CheckedFile {
    head: header::FileHead,
    /// Points the columns may reserve before decoding.
    reserve: u64,
}

/// Checks a file in the order a reader wants the reason: signature, version, point format
/// and what it lacks, the header's consistency (with the file's size, its VLRs and extended
/// VLRs), then the compression details. Nothing is allocated from a header field before it
/// is checked.
fn check_open_file(path: &Path, file: &mut File, file_size: u64) -> Result<CheckedFile, LasError> {
    let head = header::read_head(path, file, file_size)?;
    header::check_format(path, &head)?;
    header::check_consistency(path, &head)?;
    let point_bytes = header::check_point_data_bounds(path, &head)?;
    let reserve = if head.compressed {
        laz::laz_reserve_cap(head.count, point_bytes)
    } else {
        head.count
    };
    let vlr_list = vlrs::read_vlrs(path, file, &head)?;
    vlrs::check_evlrs(path, file, &head)?;
    if head.compressed {
        let layout = laz::check_laszip_vlr(path, &head, &vlr_list)?;
        laz::check_laz_chunk_table(path, file, &head, &layout)?;
    }
    Ok(CheckedFile { head, reserve })
}

/// Reads the selected points of a LAS/LAZ file as columns sorted by time.
///
/// `progress` is called with (points decoded so far, points in the file) after each batch.
pub fn read_points(
    path: &Path,
    opts: &ReadOptions,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<(PointColumns, LasInfo), LasError> {
    let io = |source| LasError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut file = File::open(path).map_err(io)?;
    let file_size = file.metadata().map_err(io)?.len();
    let checked = check_open_file(path, &mut file, file_size)?;
    drop(file);

    let mut reader = decode::open_reader(path, &checked.head)?;
    let (crs, no_crs) = match crs::header_crs(reader.header()) {
        Ok(crs) => (Some(crs), None),
        Err(why) => (None, Some(why)),
    };
    let head = checked.head;
    let extended = reader.header().point_format().is_extended;
    let reserve = checked.reserve;
    let mut cols = PointColumns::with_capacity(usize::try_from(reserve).unwrap_or(0));
    let mut selector = scanner::Selector::new(opts.scanner, extended);
    let total =
        decode::decode_points(path, &head, &mut reader, &mut selector, &mut cols, progress)?;
    drop(reader);
    let selection = selector.finish(path)?;
    if cols.is_empty() {
        return Err(scanner::nothing_selected(path, selection));
    }
    cols.shrink_to_fit();
    let has_scan_angle = cols.has_scan_angle();
    let was_reordered = cols.sort_by_time();
    let info = LasInfo {
        path: path.to_path_buf(),
        version: head.version,
        point_format: head.format,
        compressed: head.compressed,
        points_in_file: total,
        points_selected: cols.len() as u64,
        selection,
        crs,
        no_crs,
        was_reordered,
        has_scan_angle,
    };
    Ok((cols, info))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use las::{Builder, Point, Writer};

    /// Writes `points` to `path` in `format` (LAZ when the path ends in .laz).
    pub(crate) fn write_las(path: &Path, format: u8, points: &[Point], epsg: Option<u16>) {
        let mut b = Builder::from((1, 4));
        b.point_format = las::point::Format::new(format).unwrap();
        b.point_format.is_compressed = path.extension().is_some_and(|e| e == "laz");
        b.transforms = las::Vector {
            x: las::Transform {
                scale: 0.001,
                offset: 500_000.0,
            },
            y: las::Transform {
                scale: 0.001,
                offset: 4_000_000.0,
            },
            z: las::Transform {
                scale: 0.001,
                offset: 0.0,
            },
        };
        if let Some(code) = epsg {
            b.vlrs.push(geokey_vlr(code));
        }
        let header = b.into_header().unwrap();
        let mut w = Writer::from_path(path, header).unwrap();
        for p in points {
            w.write_point(p.clone()).unwrap();
        }
        w.close().unwrap();
    }

    /// A GeoKeyDirectory VLR with ProjectedCRSGeoKey (3072) = `code`.
    fn geokey_vlr(code: u16) -> las::Vlr {
        let words: [u16; 8] = [1, 1, 0, 1, 3072, 0, 1, code];
        let data = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        las::Vlr {
            user_id: "LASF_Projection".into(),
            record_id: 34735,
            description: "GeoKeyDirectoryTag".into(),
            data,
        }
    }

    pub(crate) fn pt(x: f64, y: f64, z: f64, t: f64) -> Point {
        Point {
            x,
            y,
            z,
            gps_time: Some(t),
            intensity: 7,
            ..Default::default()
        }
    }

    fn read(path: &Path, scanner: Option<u16>) -> Result<(PointColumns, LasInfo), LasError> {
        read_points(path, &ReadOptions { scanner }, &mut |_, _| {})
    }

    /// Ten points 1 m and 1 s apart written as `name` (LAS or LAZ by its extension) in
    /// point format `format`; the path and the points.
    fn ten_points(dir: &Path, name: &str, format: u8) -> (PathBuf, Vec<Point>) {
        let path = dir.join(name);
        let pts: Vec<Point> = (0..10)
            .map(|i| pt(500_000.0 + i as f64, 4_000_000.0, 0.0, i as f64))
            .collect();
        write_las(&path, format, &pts, None);
        (path, pts)
    }

    /// Regression (fuzz target `host_inputs`): LAZ items whose sizes add up to 0
    /// made the `laz` crate's parallel decompressor divide by zero.
    #[test]
    fn laz_items_that_do_not_describe_the_point_record_are_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let (path, _) = ten_points(dir.path(), "items.laz", 6);
        let good = std::fs::read(&path).unwrap();
        let vlr = good
            .windows(14)
            .position(|w| w == b"laszip encoded")
            .expect("a laszip VLR")
            - 2;
        let body = vlr + 54;
        let items = usize::from(u16::from_le_bytes([good[body + 32], good[body + 33]]));
        assert!(items >= 1);
        for size in [0u16, 29] {
            let mut bytes = good.clone();
            for k in 0..items {
                let at = body + 34 + 6 * k + 2;
                let v = if k == 0 { size } else { 0 };
                bytes[at..at + 2].copy_from_slice(&v.to_le_bytes());
            }
            std::fs::write(&path, &bytes).unwrap();
            let err = read(&path, None).unwrap_err().to_string();
            assert!(
                err.contains("items.laz") && err.contains(&format!("describe {size}-byte points")),
                "{err}"
            );
        }
        std::fs::write(&path, &good).unwrap();
        assert_eq!(read(&path, None).unwrap().0.t.len(), 10);
    }

    /// Regression (fuzz target `host_inputs`): a LAS 1.4 header whose legacy and
    /// 64-bit point counts disagree was size-checked with one and decoded with the other.
    #[test]
    fn disagreeing_point_counts_are_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let (path, _) = ten_points(dir.path(), "counts.las", 1);
        let mut bytes = std::fs::read(&path).unwrap();
        assert_eq!(u32::from_le_bytes(bytes[107..111].try_into().unwrap()), 10);
        bytes[107..111].copy_from_slice(&16_777_217u32.to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let err = read(&path, None).unwrap_err().to_string();
        assert!(
            err.contains("counts.las") && err.contains("(16777217)") && err.contains("(10)"),
            "{err}"
        );
        // Legacy count 0 with the 64-bit count set is valid LAS 1.4.
        bytes[107..111].copy_from_slice(&0u32.to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        assert_eq!(read(&path, None).unwrap().0.t.len(), 10);
    }

    /// Regression (fuzz target `host_inputs`): a LAZ chunk table claiming 2^32
    /// chunks made the `laz` crate reserve 60 GB before decoding a single entry.
    #[test]
    fn a_laz_chunk_table_claiming_more_chunks_than_bytes_is_an_error_before_any_allocation() {
        let dir = tempfile::tempdir().unwrap();
        let (path, _) = ten_points(dir.path(), "chunks.laz", 6);
        let good = std::fs::read(&path).unwrap();
        assert_eq!(read(&path, None).unwrap().0.t.len(), 10);
        let data_start = u32::from_le_bytes(good[96..100].try_into().unwrap()) as usize;
        let table = u64::from_le_bytes(good[data_start..data_start + 8].try_into().unwrap());
        let table = usize::try_from(table).unwrap();
        let mut bytes = good.clone();
        bytes[table + 4..table + 8].copy_from_slice(&u32::MAX.to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let err = read(&path, None).unwrap_err().to_string();
        assert!(
            err.contains("chunks.laz") && err.contains("chunk table claims 4294967295 chunks"),
            "{err}"
        );
        // A table offset past the end of the file.
        let mut bytes = good.clone();
        bytes[data_start..data_start + 8].copy_from_slice(&(1u64 << 40).to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let err = read(&path, None).unwrap_err().to_string();
        assert!(err.contains("past the end"), "{err}");
    }

    /// Regression (fuzz target `host_inputs`): an EVLR whose 64-bit length exceeds the file
    /// made the `las` crate try to allocate that many bytes.
    #[test]
    fn an_extended_vlr_longer_than_the_file_is_an_error_before_any_allocation() {
        let dir = tempfile::tempdir().unwrap();
        let (path, pts) = ten_points(dir.path(), "evlr.las", 6);
        let mut bytes = std::fs::read(&path).unwrap();
        let end = bytes.len() as u64;
        // One EVLR right after the points, claiming 2^62 bytes.
        bytes[235..243].copy_from_slice(&end.to_le_bytes());
        bytes[243..247].copy_from_slice(&1u32.to_le_bytes());
        let mut evlr = vec![0u8; 60];
        evlr[20..28].copy_from_slice(&(1u64 << 62).to_le_bytes());
        bytes.extend_from_slice(&evlr);
        std::fs::write(&path, &bytes).unwrap();
        let err = read(&path, None).unwrap_err().to_string();
        assert!(
            err.contains("evlr.las") && err.contains("extended VLR"),
            "{err}"
        );
        // The same file with an honest EVLR length reads.
        bytes[end as usize + 20..end as usize + 28].copy_from_slice(&0u64.to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        assert_eq!(read(&path, None).unwrap().0.t.len(), 10);
        // An EVLR as the `las` crate writes it, with a description (the length field is at
        // byte 20 of the EVLR header, the description after it), reads.
        let mut b = Builder::from((1, 4));
        b.point_format = las::point::Format::new(6).unwrap();
        b.transforms.x.offset = 500_000.0;
        b.transforms.y.offset = 4_000_000.0;
        b.evlrs.push(las::Vlr {
            user_id: "curbtrace".into(),
            record_id: 7,
            description: "a description of thirty-one chars"
                .chars()
                .take(31)
                .collect(),
            data: vec![0xff; 300],
        });
        let mut w = Writer::from_path(&path, b.into_header().unwrap()).unwrap();
        for p in &pts {
            w.write_point(p.clone()).unwrap();
        }
        w.close().unwrap();
        assert_eq!(read(&path, None).unwrap().0.t.len(), 10);
    }

    #[test]
    fn reads_columns_sorted_by_time_with_crs() {
        let dir = tempfile::tempdir().unwrap();
        for name in ["a.las", "a.laz"] {
            let path = dir.path().join(name);
            let pts = vec![
                pt(500_001.0, 4_000_002.0, 3.0, 10.5),
                pt(500_004.0, 4_000_005.0, 6.0, 10.25),
                pt(500_007.125, 4_000_008.0, 9.0, 10.5),
            ];
            write_las(&path, 6, &pts, Some(6677));
            let (c, info) = read(&path, None).unwrap();
            assert_eq!(c.t, vec![10.25, 10.5, 10.5]);
            // Stable: the two points at 10.5 keep file order.
            assert_eq!(c.x, vec![500_004.0, 500_001.0, 500_007.125]);
            assert_eq!(c.z, vec![6.0, 3.0, 9.0]);
            assert_eq!(c.intensity, vec![7, 7, 7]);
            assert_eq!(info.crs, Some(Crs::Epsg(6677)));
            assert!(info.was_reordered, "the file's times are 10.5, 10.25, 10.5");
            assert_eq!(info.point_format, 6);
            assert_eq!(info.compressed, name.ends_with("laz"));
            assert_eq!(info.points_selected, 3);
        }
    }

    #[test]
    fn every_format_with_gps_time_reads() {
        let dir = tempfile::tempdir().unwrap();
        for f in [1u8, 3, 4, 5, 6, 7, 8, 9, 10] {
            let path = dir.path().join(format!("f{f}.las"));
            let mut p = pt(500_000.5, 4_000_000.25, 1.0, 5.0);
            let fmt = las::point::Format::new(f).unwrap();
            if fmt.has_color {
                p.color = Some(las::Color::new(1, 2, 3));
            }
            if fmt.has_nir {
                p.nir = Some(4);
            }
            if fmt.has_waveform {
                p.waveform = Some(Default::default());
            }
            p.scan_angle = 12.0;
            write_las(&path, f, &[p], None);
            let (c, info) = read(&path, None).unwrap();
            assert_eq!(
                (c.x[0], c.y[0], c.t[0]),
                (500_000.5, 4_000_000.25, 5.0),
                "format {f}"
            );
            assert!((c.scan_angle_deg[0] - 12.0).abs() < 0.01, "format {f}");
            assert_eq!(info.point_format, f);
            assert_eq!(info.crs, None);
        }
    }

    #[test]
    fn scanner_channel_and_point_source_selection() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("two.las");
        let mut pts = Vec::new();
        for k in 0..6 {
            let mut p = pt(500_000.0 + k as f64, 4_000_000.0, 0.0, k as f64);
            p.scanner_channel = (k % 2) as u8;
            p.point_source_id = 40 + (k % 3) as u16;
            pts.push(p);
        }
        write_las(&path, 6, &pts, None);
        let err = read(&path, None).unwrap_err().to_string();
        assert!(
            err.contains("two.las") && err.contains("[0, 1]") && err.contains("--scanner"),
            "{err}"
        );
        let (c, info) = read(&path, Some(1)).unwrap();
        assert_eq!(c.t, vec![1.0, 3.0, 5.0]);
        assert_eq!(info.selection, ScannerSelection::Channel(1));

        // Format 1 has no scanner channel: the ID is the point source id.
        let path = dir.path().join("psid.las");
        for p in &mut pts {
            p.scanner_channel = 0;
        }
        write_las(&path, 1, &pts, None);
        let (c, info) = read(&path, Some(41)).unwrap();
        assert_eq!(c.t, vec![1.0, 4.0]);
        assert_eq!(info.selection, ScannerSelection::PointSourceId(41));
        assert_eq!(info.points_in_file, 6);
        let err = read(&path, Some(7)).unwrap_err().to_string();
        assert!(err.contains("point source id 7"), "{err}");
    }

    #[test]
    fn raw_head_parses_sizes() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("h.las");
        write_las(
            &path,
            1,
            &vec![pt(500_000.0, 4_000_000.0, 0.0, 1.0); 3],
            None,
        );
        let bytes = std::fs::read(&path).unwrap();
        let mut file = File::open(&path).unwrap();
        let h = header::read_head(&path, &mut file, bytes.len() as u64).unwrap();
        assert_eq!(h.format, 1);
        assert_eq!(h.record_len, 28);
        assert_eq!(h.count, 3);
        assert!(!h.compressed);
        assert_eq!(
            u64::from(h.offset_to_point_data) + 3 * 28,
            bytes.len() as u64
        );
    }
}
