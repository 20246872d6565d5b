//! The TOML configuration of `curbtrace extract` (`--config FILE`, `--print-config`): one
//! table per part, every field optional (`#[serde(default)]`), unknown keys rejected so a
//! typo does not silently leave a default in force.
//!
//! ```toml
//! [kernel]      # the core's parameters, sent to it in the stream's config packet
//! [replay]      # line starts and parallel chunks
//! [bend]        # seeding, tracking, post-filters (Honma et al. §2.6–2.7)
//! [rings]       # the half-arc cut of spinning sensors' files (docs/spec.md §2), tracking on rings
//! [scanners.N]  # the mount of scanner N (lever arm, roll/pitch/yaw; docs/frames.md)
//! ```
//!
//! A method adds its own table by adding a field with `#[serde(default)]` here (e.g.
//! `[qiu]`).

use crate::bend::BendParams;
use crate::replay::run::ReplayParams;
use curbtrace_core::kernel::{KernelParams, ParamsError, CONFIG_WORDS};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Errors reading a config file.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// Not valid TOML, an unknown key, or a value of the wrong type.
    #[error("{path}: {what}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// The parser's message, on one line.
        what: String,
    },
    /// The kernel rejected a parameter (out of its documented range).
    #[error("{path}: [kernel]: {what}")]
    Kernel {
        /// The file.
        path: PathBuf,
        /// Which parameter, its value and its range.
        what: ParamsError,
    },
}

/// Everything `curbtrace extract` can be told.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Config {
    /// The core's parameters (`[kernel]`): the core's own struct, with its `serde` feature
    /// (field names are the keys; each field's meaning and default are documented there).
    /// The values go to the core in the stream's config packet.
    pub kernel: KernelParams,
    /// Replay parameters (`[replay]`).
    pub replay: ReplayParams,
    /// The bend method's seeding, tracking and post-filters (`[bend]`).
    pub bend: BendParams,
    /// The plane-based method (`[qiu]`).
    pub qiu: crate::qiu::QiuParams,
    /// The half-arc cut of a spinning sensor's file and the tracker's settings on its rings
    /// (`[rings]`; files with a ring dimension only).
    pub rings: crate::rings::ArcParams,
    /// Where each scanner sits on the vehicle (`[scanners.N]`, see `mounts`); without a
    /// table a scanner's mount is zero.
    #[serde(skip_serializing_if = "crate::mounts::Mounts::is_empty")]
    pub scanners: crate::mounts::Mounts,
}

impl Config {
    /// Reads a TOML file; missing tables and keys keep their defaults.
    pub fn read(path: &Path) -> Result<Config, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let cfg: Config = toml::from_str(&text).map_err(|e| ConfigError::Parse {
            path: path.to_path_buf(),
            what: e
                .to_string()
                .split_whitespace()
                .collect::<Vec<_>>()
                .join(" "),
        })?;
        cfg.kernel_words().map_err(|what| ConfigError::Kernel {
            path: path.to_path_buf(),
            what,
        })?;
        cfg.rings.validate().map_err(|what| ConfigError::Parse {
            path: path.to_path_buf(),
            what: format!("[rings]: {what}"),
        })?;
        cfg.scanners.check().map_err(|what| ConfigError::Parse {
            path: path.to_path_buf(),
            what,
        })?;
        Ok(cfg)
    }

    /// The defaults as TOML (`--print-config`).
    pub fn default_toml() -> String {
        toml::to_string_pretty(&Config::default()).unwrap_or_default()
    }

    /// The kernel's config words for the stream's config packet, checked by the core's own
    /// `KernelParams::validate` (the check of `KernelParams::from_words`).
    pub fn kernel_words(&self) -> Result<[u32; CONFIG_WORDS], ParamsError> {
        self.kernel.validate()?;
        Ok(self.kernel.to_words())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_round_trip_through_toml() {
        let text = Config::default_toml();
        let back: Config = toml::from_str(&text).unwrap();
        assert_eq!(back, Config::default());
        assert_eq!(
            Config::default().kernel_words().unwrap(),
            KernelParams::DEFAULT.to_words()
        );
    }

    #[test]
    fn partial_file_keeps_defaults_and_unknown_keys_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("c.toml");
        std::fs::write(&p, "[replay]\nchunk_points = 1000\n").unwrap();
        let c = Config::read(&p).unwrap();
        assert_eq!(c.replay.chunk_points, 1000);
        assert_eq!(c.kernel, KernelParams::DEFAULT);
        std::fs::write(&p, "[replay]\nchunk_pionts = 1000\n").unwrap();
        let e = Config::read(&p).unwrap_err().to_string();
        assert!(
            e.contains("c.toml") && e.contains("chunk_pionts") && !e.contains('\n'),
            "{e}"
        );
    }

    #[test]
    fn the_rings_table_is_read_and_checked() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("r.toml");
        std::fs::write(&p, "[rings]\nmax_reach_m = 12.5\n").unwrap();
        let c = Config::read(&p).unwrap();
        assert_eq!(c.rings.max_reach_m, 12.5);
        assert_eq!(
            c.rings.min_range_m,
            crate::rings::ArcParams::default().min_range_m
        );
        std::fs::write(&p, "[rings]\nmin_range_m = -1.0\n").unwrap();
        let e = Config::read(&p).unwrap_err().to_string();
        assert!(e.contains("[rings]") && e.contains("min_range_m"), "{e}");
    }

    #[test]
    fn kernel_keys_and_range_errors_name_the_field() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("k.toml");
        std::fs::write(&p, "[kernel]\ntau_max_deg = 170.0\ntaubin_steps = 10\n").unwrap();
        let c = Config::read(&p).unwrap();
        assert_eq!(c.kernel.tau_max_deg, 170.0);
        assert_eq!(c.kernel.taubin_steps, 10);
        assert_eq!(c.kernel.d_b_m, KernelParams::DEFAULT.d_b_m);
        std::fs::write(&p, "[kernel]\ntau_max_deg = 30.0\n").unwrap();
        let e = Config::read(&p).unwrap_err().to_string();
        assert!(
            e.ends_with(
                "k.toml: [kernel]: tau_max_deg is NaN, infinite or outside its range (tau_min_deg, 180]"
            ),
            "{e}"
        );
        std::fs::write(&p, "[kernel]\ntau_mx_deg = 30.0\n").unwrap();
        let e = Config::read(&p).unwrap_err().to_string();
        assert!(e.contains("k.toml") && e.contains("tau_mx_deg"), "{e}");
    }
}
