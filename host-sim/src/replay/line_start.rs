//! Where scanlines start in a LAS file (docs/spec.md §2): the core's assembler splits lines at the
//! stream's line-start flag when the source sets it. A LAS file has no line numbers, so the
//! replay derives them:
//!
//! 1. **Scan angle wrapping** (preferred). A rotating mirror's angle grows (or shrinks)
//!    steadily through one revolution and jumps back by close to 360° where the line is
//!    split, at the top (LAS: 0° is nadir, ±180° straight up). Returns from the open sky are
//!    often missing, so the jump can be much smaller than 360° (from +60° to −60° over an
//!    open road), but it is always *against* the direction of rotation, which consecutive
//!    points otherwise never are by more than noise. Rule: the rotation direction is the sign
//!    that most consecutive non-zero differences have; a line starts at point i when
//!    `(sa[i] − sa[i−1]) · direction < −wrap_min_deg`. Legacy formats clamp the angle to
//!    ±90°, which still leaves a backward jump of about 180° at the top.
//! 2. **GPS time and the line period** (`[replay] line_period_s` in the config), when the
//!    scan angle carries no information: line k holds the points with
//!    ⌊(t − t₀) / period⌋ = k.
//! 3. **Neither**: no flags; the core splits lines itself (its no-flag rule, docs/spec.md §2).

/// How line starts are derived (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LineRule {
    /// From the scan angle wrapping against the rotation `direction` (+1 or −1).
    ScanAngle {
        /// +1 when the angle grows through a line, −1 when it shrinks.
        direction: f32,
        /// Smallest backward jump taken as a wrap, degrees.
        wrap_min_deg: f32,
    },
    /// From GPS time: line k = ⌊(t − t0) / period⌋.
    Period {
        /// Time of the first point, seconds.
        t0: f64,
        /// Line period, seconds.
        period_s: f64,
    },
    /// No flags: the core splits.
    None,
}

/// The line-start part of the `[replay]` config table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineStartParams {
    /// Smallest backward jump of the scan angle taken as the wrap between two lines,
    /// degrees. Consecutive returns of a rotating scanner differ by well under a degree; a
    /// line's own returns never step back. 45° leaves room for legacy formats' whole-degree
    /// angles and for sky gaps of up to 315°. Not in the paper (which gets lines from the
    /// scanner).
    pub wrap_min_deg: f32,
    /// Line period in seconds for files without scan angles (0 = unknown: the core splits).
    pub line_period_s: f64,
}

impl Default for LineStartParams {
    fn default() -> Self {
        Self {
            wrap_min_deg: 45.0,
            line_period_s: 0.0,
        }
    }
}

impl LineRule {
    /// Chooses the rule for a file: the scan angle if it varies and has a clear rotation
    /// direction, else the line period if one is configured, else none.
    pub fn choose(scan_angle_deg: &[f32], t: &[f64], params: &LineStartParams) -> LineRule {
        let (mut up, mut down) = (0u64, 0u64);
        for w in scan_angle_deg.windows(2) {
            let d = w[1] - w[0];
            if d > 0.0 {
                up += 1;
            } else if d < 0.0 {
                down += 1;
            }
        }
        // A rotating scanner steps the same way for all but one pair per line; demand a
        // clear majority so that noise or unrelated angle columns fall through.
        if up + down > 0 && (up > 4 * down || down > 4 * up) {
            return LineRule::ScanAngle {
                direction: if up > down { 1.0 } else { -1.0 },
                wrap_min_deg: params.wrap_min_deg,
            };
        }
        if params.line_period_s > 0.0 {
            if let Some(&t0) = t.first() {
                return LineRule::Period {
                    t0,
                    period_s: params.line_period_s,
                };
            }
        }
        LineRule::None
    }

    /// True when point `i` starts a new line. Point 0 always does, unless the rule is
    /// [`LineRule::None`].
    #[inline]
    pub fn is_start(&self, i: usize, scan_angle_deg: &[f32], t: &[f64]) -> bool {
        match *self {
            LineRule::ScanAngle {
                direction,
                wrap_min_deg,
            } => i == 0 || (scan_angle_deg[i] - scan_angle_deg[i - 1]) * direction < -wrap_min_deg,
            LineRule::Period { t0, period_s } => {
                i == 0 || ((t[i] - t0) / period_s).floor() != ((t[i - 1] - t0) / period_s).floor()
            }
            LineRule::None => false,
        }
    }

    /// Whether the rule sets flags at all (chunks for parallel replay can only be cut at
    /// flagged line starts).
    pub fn flags_lines(&self) -> bool {
        !matches!(self, LineRule::None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three revolutions, angles stepping by `step` degrees, returns only within ±`fov`
    /// (the sky gives none).
    fn revolutions(step: f32, fov: f32) -> Vec<f32> {
        let mut v = Vec::new();
        for _ in 0..3 {
            let mut a = -180.0f32;
            while a < 180.0 {
                if a.abs() <= fov {
                    v.push(a);
                }
                a += step.abs();
            }
        }
        if step < 0.0 {
            v.iter_mut().for_each(|a| *a = -*a);
        }
        v
    }

    fn starts(rule: &LineRule, sa: &[f32], t: &[f64]) -> Vec<usize> {
        (0..sa.len().max(t.len()))
            .filter(|&i| rule.is_start(i, sa, t))
            .collect()
    }

    #[test]
    fn wrap_is_found_for_both_rotation_directions_and_sky_gaps() {
        let p = LineStartParams::default();
        for step in [0.5f32, -0.5] {
            for fov in [180.0f32, 60.0] {
                let sa = revolutions(step, fov);
                let per_line = sa.len() / 3;
                let rule = LineRule::choose(&sa, &[], &p);
                assert!(matches!(rule, LineRule::ScanAngle { .. }), "{rule:?}");
                assert_eq!(
                    starts(&rule, &sa, &[]),
                    vec![0, per_line, 2 * per_line],
                    "step {step} fov {fov}"
                );
            }
        }
    }

    #[test]
    fn legacy_clamped_angles_still_wrap() {
        // ±90° clamp of a 360° scanner: long runs of equal angles, then a 180° jump back.
        let sa: Vec<f32> = revolutions(1.0, 180.0)
            .iter()
            .map(|a| a.clamp(-90.0, 90.0).round())
            .collect();
        let rule = LineRule::choose(&sa, &[], &LineStartParams::default());
        assert_eq!(starts(&rule, &sa, &[]), vec![0, 360, 720]);
    }

    #[test]
    fn line_period_when_scan_angles_are_flat() {
        let sa = vec![0.0f32; 10];
        let t: Vec<f64> = (0..10).map(|k| 100.0 + k as f64 * 0.004).collect();
        let p = LineStartParams {
            line_period_s: 0.0101,
            ..Default::default()
        };
        let rule = LineRule::choose(&sa, &t, &p);
        // Lines of 10.1 ms from t0 (boundaries 0.2 ms or more from any point):
        // 0, 4, 8 ms | 12, 16, 20 | 24, 28 | 32, 36.
        assert_eq!(starts(&rule, &sa, &t), vec![0, 3, 6, 8]);
        let rule = LineRule::choose(&sa, &t, &LineStartParams::default());
        assert_eq!(rule, LineRule::None);
        assert!(starts(&rule, &sa, &t).is_empty());
    }
}
