//! The TOML configuration of `curbtrace extract` (`--config FILE`, `--print-config`): one
//! table per part, every field optional (`#[serde(default)]`), unknown keys rejected so a
//! typo does not silently leave a default in force.
//!
//! ```toml
//! [kernel]      # the core's parameters, sent to it in the stream's config packet
//! [replay]      # line starts and parallel chunks
//! [bend]        # seeding, tracking, post-filters (Honma et al. §2.6–2.7)
//! ```
//!
//! A method adds its own table by adding a field with `#[serde(default)]` here (e.g.
//! `[qiu]`).

use crate::bend::BendParams;
use crate::replay::run::ReplayParams;
use curbtrace_core::kernel::{KernelParams, CONFIG_WORDS};
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
        /// Which parameter.
        what: String,
    },
}

/// Everything `curbtrace extract` can be told.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Config {
    /// The core's parameters (`[kernel]`).
    pub kernel: KernelConfig,
    /// Replay parameters (`[replay]`).
    pub replay: ReplayParams,
    /// The bend method's seeding, tracking and post-filters (`[bend]`).
    pub bend: BendParams,
    /// The plane-based method (`[qiu]`).
    pub qiu: crate::qiu::QiuParams,
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
        Ok(cfg)
    }

    /// The defaults as TOML (`--print-config`).
    pub fn default_toml() -> String {
        toml::to_string_pretty(&Config::default()).unwrap_or_default()
    }

    /// The kernel's config words for the stream's config packet, checked by the core's own
    /// `KernelParams::from_words`.
    pub fn kernel_words(&self) -> Result<[u32; CONFIG_WORDS], String> {
        let p = self.kernel.to_params();
        let words = p.to_words();
        KernelParams::from_words(&words).map_err(|e| format!("{e:?}"))?;
        Ok(words)
    }
}

/// The `[kernel]` table: a serde mirror of `curbtrace_core::kernel::KernelParams` (the core
/// is `no_std` without serde); each field's meaning and default are documented there.
/// Defaults are the core's `KernelParams::DEFAULT`; the values go to the core in the
/// stream's config packet and are checked by the core itself.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct KernelConfig {
    /// d_b: neighbour distance of the bend angle, metres (§2.3).
    pub d_b_m: f32,
    /// Irregular-point threshold on |ρ| of the raw line, degrees (§2.4).
    pub irregular_deg: f32,
    /// τ_min: lower bound of a peak's ρ, degrees (§2.6).
    pub tau_min_deg: f32,
    /// τ_max: upper bound of a peak's ρ, degrees (§2.6).
    pub tau_max_deg: f32,
    /// Taubin smoothing steps (§2.5).
    pub taubin_steps: u32,
    /// Taubin λ (§2.5).
    pub taubin_lambda: f32,
    /// Taubin μ (§2.5).
    pub taubin_mu: f32,
    /// Gap that splits a line into separately smoothed pieces, metres (0 = never).
    pub smooth_gap_m: f32,
    /// Assembly: pause that ends a line without flags, ns (0 = off).
    pub split_gap_ns: u32,
    /// Assembly: when the geometric split rule is active (0 = auto, 1 = always, 2 = never).
    pub split_geometry: u32,
}

impl Default for KernelConfig {
    fn default() -> Self {
        Self::from_params(&KernelParams::DEFAULT)
    }
}

impl KernelConfig {
    /// From the core's struct.
    pub fn from_params(p: &KernelParams) -> Self {
        Self {
            d_b_m: p.d_b_m,
            irregular_deg: p.irregular_deg,
            tau_min_deg: p.tau_min_deg,
            tau_max_deg: p.tau_max_deg,
            taubin_steps: p.taubin_steps,
            taubin_lambda: p.taubin_lambda,
            taubin_mu: p.taubin_mu,
            smooth_gap_m: p.smooth_gap_m,
            split_gap_ns: p.split_gap_ns,
            split_geometry: p.split_geometry,
        }
    }

    /// To the core's struct.
    pub fn to_params(&self) -> KernelParams {
        KernelParams {
            d_b_m: self.d_b_m,
            irregular_deg: self.irregular_deg,
            tau_min_deg: self.tau_min_deg,
            tau_max_deg: self.tau_max_deg,
            taubin_steps: self.taubin_steps,
            taubin_lambda: self.taubin_lambda,
            taubin_mu: self.taubin_mu,
            smooth_gap_m: self.smooth_gap_m,
            split_gap_ns: self.split_gap_ns,
            split_geometry: self.split_geometry,
        }
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
        assert_eq!(c.kernel, KernelConfig::default());
        std::fs::write(&p, "[replay]\nchunk_pionts = 1000\n").unwrap();
        let e = Config::read(&p).unwrap_err().to_string();
        assert!(
            e.contains("c.toml") && e.contains("chunk_pionts") && !e.contains('\n'),
            "{e}"
        );
    }
}
