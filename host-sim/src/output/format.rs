//! The choice of an output format by the extension of the output path, and the one entry
//! point that writes edges in it (`docs/output-formats.md`).

use crate::model::GeoJsonError;
use std::path::Path;

/// A file format the edges can be written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum OutputFormat {
    /// GeoJSON FeatureCollection of LineStrings with the legacy `crs` member.
    GeoJson,
    /// Plain vertex lists: `edge,side,vertex,x,y,z`.
    Csv,
    /// OGC GeoPackage (SQLite): one feature table `edges`.
    GeoPackage,
    /// FlatGeobuf: one layer `edges` with a spatial index.
    FlatGeobuf,
    /// AutoCAD DXF: 3D polylines on one layer per line kind and class.
    Dxf,
}

/// Every extension `-o` accepts, in the order error messages list them.
pub const SUPPORTED_EXTENSIONS: [&str; 6] = ["geojson", "json", "csv", "gpkg", "fgb", "dxf"];

impl OutputFormat {
    /// All formats.
    pub const ALL: [OutputFormat; 5] = [
        OutputFormat::GeoJson,
        OutputFormat::Csv,
        OutputFormat::GeoPackage,
        OutputFormat::FlatGeobuf,
        OutputFormat::Dxf,
    ];

    /// The format named by an extension (without the dot, any case), if any.
    pub fn from_extension(ext: &str) -> Option<Self> {
        match ext.to_ascii_lowercase().as_str() {
            "geojson" | "json" => Some(OutputFormat::GeoJson),
            "csv" => Some(OutputFormat::Csv),
            "gpkg" => Some(OutputFormat::GeoPackage),
            "fgb" => Some(OutputFormat::FlatGeobuf),
            "dxf" => Some(OutputFormat::Dxf),
            _ => None,
        }
    }

    /// The format named by the extension of `path`; an error names the path, the extension
    /// and the supported list.
    pub fn from_path(path: &Path) -> Result<Self, OutputError> {
        let ext = path.extension().map(|e| e.to_string_lossy().into_owned());
        match ext.as_deref().and_then(Self::from_extension) {
            Some(f) => Ok(f),
            None => Err(OutputError::UnknownExtension {
                path: path.display().to_string(),
                ext,
            }),
        }
    }

    /// The spelling on the command line (`--format NAME`): the main extension.
    pub fn flag_name(self) -> &'static str {
        match self {
            OutputFormat::GeoJson => "geojson",
            OutputFormat::Csv => "csv",
            OutputFormat::GeoPackage => "gpkg",
            OutputFormat::FlatGeobuf => "fgb",
            OutputFormat::Dxf => "dxf",
        }
    }

    /// The name GIS tools use for the format (GDAL's driver name where there is one).
    pub fn name(self) -> &'static str {
        match self {
            OutputFormat::GeoJson => "GeoJSON",
            OutputFormat::Csv => "CSV",
            OutputFormat::GeoPackage => "GPKG",
            OutputFormat::FlatGeobuf => "FlatGeobuf",
            OutputFormat::Dxf => "DXF",
        }
    }
}

/// Errors choosing an output format or writing edges in it. Every message names the file.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The output path has no extension, or one no format answers to.
    #[error(
        "{path}: {}; supported: {}",
        match ext {
            Some(e) => format!("unknown output extension \".{e}\""),
            None => "the output file has no extension".to_string(),
        },
        supported_list()
    )]
    UnknownExtension {
        /// The output path.
        path: String,
        /// Its extension, if it has one.
        ext: Option<String>,
    },
    /// `--format` and the extension of `-o` name different formats.
    #[error("{path}: --format {flag} conflicts with the extension \".{ext}\" ({by_extension})")]
    Conflict {
        /// The output path.
        path: String,
        /// The format `--format` names, as spelt there.
        flag: &'static str,
        /// The extension of the path.
        ext: String,
        /// The format the extension names.
        by_extension: &'static str,
    },
    /// Writing GeoJSON failed.
    #[error(transparent)]
    GeoJson(#[from] GeoJsonError),
    /// The file could not be created or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// An encoder refused the data.
    #[error("{path}: writing {format}: {what}")]
    Encode {
        /// The file.
        path: String,
        /// The format being written.
        format: &'static str,
        /// What the encoder said.
        what: String,
    },
}

impl OutputError {
    /// An encoder's error for `path`.
    pub(crate) fn encode(path: &Path, format: OutputFormat, what: impl ToString) -> Self {
        OutputError::Encode {
            path: path.display().to_string(),
            format: format.name(),
            what: what.to_string(),
        }
    }

    /// An I/O error for `path`.
    pub(crate) fn io(path: &Path, source: std::io::Error) -> Self {
        OutputError::Io {
            path: path.display().to_string(),
            source,
        }
    }
}

fn supported_list() -> String {
    SUPPORTED_EXTENSIONS
        .iter()
        .map(|e| format!(".{e}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The format to write: the one `flag` names (from `--format`) when given, which must agree
/// with the extension when the extension names a format; else the one the extension names.
pub fn resolve(path: &Path, flag: Option<OutputFormat>) -> Result<OutputFormat, OutputError> {
    let by_extension = OutputFormat::from_path(path);
    match (flag, by_extension) {
        (None, by_ext) => by_ext,
        (Some(f), Ok(e)) if f == e => Ok(f),
        (Some(f), Ok(e)) => Err(OutputError::Conflict {
            path: path.display().to_string(),
            flag: f.flag_name(),
            ext: path
                .extension()
                .map(|x| x.to_string_lossy().into_owned())
                .unwrap_or_default(),
            by_extension: e.name(),
        }),
        // An explicit --format covers any file name (`-o edges.txt --format csv`).
        (Some(f), Err(_)) => Ok(f),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_supported_extension_names_a_format_in_any_case() {
        for ext in SUPPORTED_EXTENSIONS {
            let p = format!("out/edges.{ext}");
            assert!(OutputFormat::from_path(Path::new(&p)).is_ok(), "{p}");
            let upper = format!("out/edges.{}", ext.to_ascii_uppercase());
            assert!(
                OutputFormat::from_path(Path::new(&upper)).is_ok(),
                "{upper}"
            );
        }
        let f = |p: &str| OutputFormat::from_path(Path::new(p)).unwrap();
        assert_eq!(f("a.geojson"), OutputFormat::GeoJson);
        assert_eq!(f("a.json"), OutputFormat::GeoJson);
        assert_eq!(f("a.csv"), OutputFormat::Csv);
        assert_eq!(f("a.GPKG"), OutputFormat::GeoPackage);
        assert_eq!(f("a.b.fgb"), OutputFormat::FlatGeobuf);
        assert_eq!(f("a.dxf"), OutputFormat::Dxf);
    }

    #[test]
    fn an_unknown_extension_names_the_file_the_extension_and_the_list() {
        let err = OutputFormat::from_path(Path::new("out/edges.shp"))
            .unwrap_err()
            .to_string();
        assert_eq!(
            err,
            "out/edges.shp: unknown output extension \".shp\"; supported: \
             .geojson, .json, .csv, .gpkg, .fgb, .dxf"
        );
        let err = OutputFormat::from_path(Path::new("out/edges"))
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("out/edges: the output file has no extension; supported: .geojson"),
            "{err}"
        );
    }

    #[test]
    fn the_format_flag_must_agree_with_a_known_extension() {
        let p = Path::new("edges.csv");
        assert_eq!(resolve(p, None).unwrap(), OutputFormat::Csv);
        assert_eq!(
            resolve(p, Some(OutputFormat::Csv)).unwrap(),
            OutputFormat::Csv
        );
        let err = resolve(Path::new("edges.gpkg"), Some(OutputFormat::Csv))
            .unwrap_err()
            .to_string();
        assert_eq!(
            err,
            "edges.gpkg: --format csv conflicts with the extension \".gpkg\" (GPKG)"
        );
        assert_eq!(
            resolve(Path::new("edges.txt"), Some(OutputFormat::Csv)).unwrap(),
            OutputFormat::Csv
        );
        assert!(resolve(Path::new("edges.txt"), None).is_err());
    }
}
