//! The file's CRS, kept for the output: the WKT VLR, else the EPSG code of the GeoTIFF
//! projected (else geodetic) key; or why there is none.

use crate::model::Crs;

/// GeoTIFF key value for "user-defined" (GeoTIFF 1.1, §7.1.4).
const USER_DEFINED: u16 = 32767;

/// Why a file gives the output no CRS.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoCrs {
    /// Neither a WKT nor a GeoTIFF CRS record.
    Absent,
    /// GeoTIFF keys that define the CRS by parameters (key value 32767), with no EPSG code.
    UserDefined,
    /// GeoTIFF keys that name no EPSG code in 1024–32766, or that cannot be read.
    Unrecognised,
}

impl std::fmt::Display for NoCrs {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            NoCrs::Absent => "the input has no CRS record (no WKT, no GeoTIFF keys)",
            NoCrs::UserDefined => {
                "the input's CRS is user-defined (GeoTIFF key value 32767), which has no EPSG code"
            }
            NoCrs::Unrecognised => {
                "the input's GeoTIFF keys name no EPSG code curbtrace recognises"
            }
        })
    }
}

/// The CRS of a header: the WKT VLR, else EPSG from the GeoTIFF projected (else geodetic)
/// key; else why there is none.
pub(super) fn header_crs(header: &las::Header) -> Result<Crs, NoCrs> {
    if let Some(bytes) = header.get_wkt_crs_bytes() {
        let wkt = String::from_utf8_lossy(bytes)
            .trim_end_matches('\0')
            .trim()
            .to_string();
        if !wkt.is_empty() {
            return Ok(Crs::Wkt(wkt));
        }
    }
    let gt = match header.get_geotiff_crs() {
        Ok(Some(gt)) => gt,
        Ok(None) => return Err(NoCrs::Absent),
        Err(_) => return Err(NoCrs::Unrecognised),
    };
    let keys = [
        gt.get_projected_crs_geo_key_value(),
        gt.get_geodetic_crs_geo_key_value(),
    ];
    if let Some(code) = keys.iter().flatten().find(|c| (1024..=32766).contains(*c)) {
        return Ok(Crs::Epsg(u32::from(*code)));
    }
    Err(if keys.contains(&Some(USER_DEFINED)) {
        NoCrs::UserDefined
    } else {
        NoCrs::Unrecognised
    })
}
