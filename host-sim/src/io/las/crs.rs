//! The file's CRS, kept for the output: the WKT VLR, else the EPSG code of the GeoTIFF
//! projected (else geodetic) key.

use crate::model::Crs;

/// The CRS of a header: EPSG from the GeoTIFF projected (else geodetic) key, or the WKT VLR.
pub(super) fn header_crs(header: &las::Header) -> Option<Crs> {
    if let Some(bytes) = header.get_wkt_crs_bytes() {
        let wkt = String::from_utf8_lossy(bytes)
            .trim_end_matches('\0')
            .trim()
            .to_string();
        if !wkt.is_empty() {
            return Some(Crs::Wkt(wkt));
        }
    }
    let gt = header.get_geotiff_crs().ok().flatten()?;
    let code = gt
        .get_projected_crs_geo_key_value()
        .filter(|c| (1024..=32766).contains(c))
        .or_else(|| {
            gt.get_geodetic_crs_geo_key_value()
                .filter(|c| (1024..=32766).contains(c))
        })?;
    Some(Crs::Epsg(u32::from(code)))
}
