//! The point inputs of `curbtrace extract`: each argument is a LAS/LAZ file, a directory
//! (its `*.las` and `*.laz` files) or a glob pattern (`strips/*.laz`, for shells that do
//! not expand it). The result is a list of files without duplicates; their order does not
//! matter, the campaign orders them by time.

use std::path::{Path, PathBuf};

/// Errors expanding the inputs.
#[derive(Debug, thiserror::Error)]
pub enum FilesError {
    /// A path that is neither a file, a directory nor a pattern that matches a file.
    #[error("{0}: no such file or directory, and no file matches it as a pattern")]
    NotFound(PathBuf),
    /// A directory without LAS/LAZ files.
    #[error("{0}: the directory holds no .las or .laz file")]
    EmptyDirectory(PathBuf),
    /// A directory that cannot be listed.
    #[error("{path}: {source}")]
    Io {
        /// The directory.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A malformed glob pattern.
    #[error("{pattern}: not a valid pattern: {what}")]
    Pattern {
        /// The pattern.
        pattern: String,
        /// The parser's message.
        what: String,
    },
}

fn is_point_file(p: &Path) -> bool {
    p.is_file()
        && p.extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("las") || e.eq_ignore_ascii_case("laz"))
}

/// Expands files, directories and glob patterns into the list of point files.
pub fn expand(inputs: &[PathBuf]) -> Result<Vec<PathBuf>, FilesError> {
    let mut out = Vec::new();
    for input in inputs {
        if input.is_file() {
            out.push(input.clone());
        } else if input.is_dir() {
            let rd = std::fs::read_dir(input).map_err(|source| FilesError::Io {
                path: input.clone(),
                source,
            })?;
            let mut found: Vec<PathBuf> = rd
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| is_point_file(p))
                .collect();
            if found.is_empty() {
                return Err(FilesError::EmptyDirectory(input.clone()));
            }
            found.sort();
            out.extend(found);
        } else {
            let pattern = input.to_string_lossy().to_string();
            let paths = glob::glob(&pattern).map_err(|e| FilesError::Pattern {
                pattern: pattern.clone(),
                what: e.msg.to_string(),
            })?;
            let mut found: Vec<PathBuf> = paths
                .filter_map(Result::ok)
                .filter(|p| p.is_file())
                .collect();
            if found.is_empty() {
                return Err(FilesError::NotFound(input.clone()));
            }
            found.sort();
            out.extend(found);
        }
    }
    let mut seen = std::collections::HashSet::new();
    out.retain(|p| seen.insert(std::fs::canonicalize(p).unwrap_or_else(|_| p.clone())));
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directory_glob_and_duplicates() {
        let d = tempfile::tempdir().unwrap();
        for n in ["b.laz", "a.las", "c.txt"] {
            std::fs::write(d.path().join(n), b"x").unwrap();
        }
        let got = expand(&[d.path().to_path_buf(), d.path().join("*.laz")]).unwrap();
        assert_eq!(got, vec![d.path().join("a.las"), d.path().join("b.laz")]);
        let err = expand(&[d.path().join("nothing*.laz")])
            .unwrap_err()
            .to_string();
        assert!(err.contains("nothing*.laz"), "{err}");
    }
}
