//! Scanner mounts: where each scanner sits on the vehicle (docs/frames.md, "Mounts").
//!
//! The trajectory is the path of the vehicle's reference point (the IMU or the GNSS
//! antenna's projection, whatever the calibration report names). Each scanner has a mount
//! relative to it: a lever arm in the body frame (forward, left, up, metres) and the
//! scanner's roll, pitch and yaw (degrees). A scanner without a mount sits at the reference
//! point, which is how a one-scanner trajectory of the scanner's own origin is read.
//!
//! In the config the mounts are one table per scanner key — the LAS 1.4 scanner channel,
//! or the point source id where the file uses no channels, as `--scanner` takes it:
//!
//! ```toml
//! [scanners.1]
//! lever_arm_m = [0.0, -0.8, 0.0]   # forward, left, up
//! yaw_deg = -45.0
//! ```
//!
//! The projection (step a) measures x′ across the driving direction and z′ up from the
//! scanner's origin: the lever arm moves that origin. The angles describe the scan plane;
//! across the road a yawed or tilted plane cuts a curb in the same profile, so the
//! projection does not use them (they are checked and kept with the mount).

use crate::io::trajectory::{Pose, Trajectory};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// One scanner's mount relative to the trajectory's reference point.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Mount {
    /// Lever arm in the body frame: forward, left, up, metres.
    pub lever_arm_m: [f64; 3],
    /// Roll of the scanner, degrees (right side down positive).
    pub roll_deg: f64,
    /// Pitch of the scanner, degrees (nose up positive).
    pub pitch_deg: f64,
    /// Yaw of the scanner, degrees (turned left positive).
    pub yaw_deg: f64,
}

/// Longest lever arm accepted, metres: a scanner is on the vehicle.
pub const MAX_LEVER_ARM_M: f64 = 10.0;

impl Mount {
    /// True for the zero mount (the scanner at the reference point).
    pub fn is_zero(&self) -> bool {
        *self == Mount::default()
    }

    /// Checks the values: finite, lever arm within [`MAX_LEVER_ARM_M`], angles within ±360°.
    pub fn check(&self) -> Result<(), String> {
        let l = self.lever_arm_m;
        if !l
            .iter()
            .all(|v| v.is_finite() && v.abs() <= MAX_LEVER_ARM_M)
        {
            return Err(format!(
                "lever_arm_m {l:?}: each component finite and within ±{MAX_LEVER_ARM_M} m"
            ));
        }
        for (name, v) in [
            ("roll_deg", self.roll_deg),
            ("pitch_deg", self.pitch_deg),
            ("yaw_deg", self.yaw_deg),
        ] {
            if !(v.is_finite() && v.abs() <= 360.0) {
                return Err(format!("{name} {v}: finite and within ±360°"));
            }
        }
        Ok(())
    }

    /// The scanner origin's trajectory: every pose moved by the lever arm turned by the
    /// vehicle's attitude at that pose (heading, pitch, roll as in docs/frames.md). The
    /// attitude stays the vehicle's. The zero mount gives the trajectory unchanged.
    pub fn apply(&self, traj: &Trajectory) -> Trajectory {
        if self.lever_arm_m == [0.0; 3] {
            return traj.clone();
        }
        let [a, b, c] = self.lever_arm_m;
        let samples = traj
            .samples
            .iter()
            .map(|p| {
                let [f, l, u] = body_axes(p.heading_deg, p.pitch_deg, p.roll_deg);
                Pose {
                    x: p.x + a * f[0] + b * l[0] + c * u[0],
                    y: p.y + a * f[1] + b * l[1] + c * u[1],
                    z: p.z + a * f[2] + b * l[2] + c * u[2],
                    ..*p
                }
            })
            .collect();
        Trajectory { samples }
    }
}

/// Body axes (forward, left, up) in world coordinates: forward `(sin h, cos h, 0)` and
/// left `(−cos h, sin h, 0)` for heading h; pitch (nose up) turns forward and up about
/// left, then roll (right side down) turns left and up about the new forward axis.
pub fn body_axes(heading_deg: f64, pitch_deg: f64, roll_deg: f64) -> [[f64; 3]; 3] {
    let (sh, ch) = heading_deg.to_radians().sin_cos();
    let (sp, cp) = pitch_deg.to_radians().sin_cos();
    let (sr, cr) = roll_deg.to_radians().sin_cos();
    let (f, l, u) = ([sh, ch, 0.0], [-ch, sh, 0.0], [0.0, 0.0, 1.0]);
    let lin = |a: [f64; 3], x: f64, b: [f64; 3], y: f64| {
        [
            a[0] * x + b[0] * y,
            a[1] * x + b[1] * y,
            a[2] * x + b[2] * y,
        ]
    };
    let f1 = lin(f, cp, u, sp);
    let u1 = lin(u, cp, f, -sp);
    let l2 = lin(l, cr, u1, sr);
    let u2 = lin(u1, cr, l, -sr);
    [f1, l2, u2]
}

/// The mounts of a system, by scanner key (`[scanners]` in the config, or a mounts file
/// holding only that table).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Mounts(pub BTreeMap<String, Mount>);

/// A mounts file: the `[scanners]` table alone (what `curbtrace simulate --scanners 2`
/// writes as `mounts.toml`; `--config` reads the same text).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MountsFile {
    /// The mounts by scanner key.
    pub scanners: Mounts,
}

impl Mounts {
    /// True when no scanner has a mount.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The mount of scanner `key`; the zero mount where none is given.
    pub fn get(&self, key: u16) -> Mount {
        self.0.get(&key.to_string()).copied().unwrap_or_default()
    }

    /// Sets the mount of scanner `key`.
    pub fn set(&mut self, key: u16, m: Mount) {
        self.0.insert(key.to_string(), m);
    }

    /// Checks every key (a scanner number 0–65535) and every mount.
    pub fn check(&self) -> Result<(), String> {
        for (k, m) in &self.0 {
            if k.parse::<u16>().is_err() {
                return Err(format!(
                    "[scanners.{k}]: the key is a scanner channel or point source id (0–65535)"
                ));
            }
            m.check().map_err(|w| format!("[scanners.{k}]: {w}"))?;
        }
        Ok(())
    }

    /// Reads a mounts file (TOML with a `[scanners]` table); a one-line error naming the
    /// file otherwise.
    pub fn read(path: &std::path::Path) -> Result<Mounts, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let f: MountsFile = toml::from_str(&text).map_err(|e| {
            let w = e.to_string();
            format!(
                "{}: {}",
                path.display(),
                w.split_whitespace().collect::<Vec<_>>().join(" ")
            )
        })?;
        f.scanners
            .check()
            .map_err(|w| format!("{}: {w}", path.display()))?;
        Ok(f.scanners)
    }

    /// The mounts file's text.
    pub fn to_toml(&self) -> String {
        toml::to_string_pretty(&MountsFile {
            scanners: self.clone(),
        })
        .unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pose(t: f64, heading: f64) -> Pose {
        Pose {
            t,
            x: 100.0,
            y: 200.0,
            z: 3.0,
            roll_deg: 0.0,
            pitch_deg: 0.0,
            heading_deg: heading,
        }
    }

    #[test]
    fn a_lever_arm_moves_the_origin_in_the_body_frame() {
        // Driving east (90°): forward is +x, left is +y.
        let traj = Trajectory {
            samples: vec![pose(0.0, 90.0), pose(1.0, 90.0)],
        };
        let m = Mount {
            lever_arm_m: [0.5, -0.8, 0.2],
            yaw_deg: -45.0,
            ..Mount::default()
        };
        let t = m.apply(&traj);
        let p = t.samples[0];
        assert!((p.x - 100.5).abs() < 1e-12 && (p.y - 199.2).abs() < 1e-12);
        assert!((p.z - 3.2).abs() < 1e-12 && p.heading_deg == 90.0);
        // The zero mount leaves the trajectory as it is.
        let z = Mount::default().apply(&traj);
        assert_eq!(z.samples, traj.samples);
    }

    #[test]
    fn mounts_read_from_toml_and_bad_ones_are_refused() {
        let m: MountsFile =
            toml::from_str("[scanners.1]\nlever_arm_m = [0.0, -0.8, 0.0]\nyaw_deg = -45.0\n")
                .unwrap();
        assert!(m.scanners.check().is_ok());
        assert_eq!(m.scanners.get(1).yaw_deg, -45.0);
        assert!(m.scanners.get(0).is_zero());
        let back: MountsFile = toml::from_str(&m.scanners.to_toml()).unwrap();
        assert_eq!(back, m);
        let bad: MountsFile = toml::from_str("[scanners.x]\nyaw_deg = 1.0\n").unwrap();
        assert!(bad.scanners.check().unwrap_err().contains("[scanners.x]"));
        let far: MountsFile = toml::from_str("[scanners.0]\nlever_arm_m = [0, 40, 0]\n").unwrap();
        assert!(far.scanners.check().unwrap_err().contains("lever_arm_m"));
        assert!(toml::from_str::<MountsFile>("[scanners.0]\nlever = 1\n").is_err());
    }
}
