//! The points as columns, and the decoding of raw point records into them.
//!
//! Columns: x, y, z, t as `f64` (32 B), intensity `u16` (2 B), scan angle `f32` (4 B),
//! scanner channel `u8` (1 B): 39 B per selected point.

/// The selected points as columns, sorted by GPS time (stable: equal times keep file
/// order). Index `i` of every column is point `i`, the tag the core carries.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointColumns {
    /// World X, LAS CRS, metres.
    pub x: Vec<f64>,
    /// World Y, LAS CRS, metres.
    pub y: Vec<f64>,
    /// World Z, metres.
    pub z: Vec<f64>,
    /// GPS time, seconds, in the file's time base, non-decreasing.
    pub t: Vec<f64>,
    /// Intensity as stored.
    pub intensity: Vec<u16>,
    /// Scan angle, degrees (legacy formats: whole degrees; 6–10: 0.006° steps).
    pub scan_angle_deg: Vec<f32>,
    /// Channel key: the LAS 1.4 scanner channel (formats 6–10), 0 in legacy formats.
    pub channel: Vec<u8>,
}

impl PointColumns {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// True when there is no point.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// First and last time, or `None` when empty.
    pub fn time_range(&self) -> Option<(f64, f64)> {
        Some((*self.t.first()?, *self.t.last()?))
    }

    /// Empty columns with room for `n` points.
    pub fn with_capacity(n: usize) -> Self {
        Self {
            x: Vec::with_capacity(n),
            y: Vec::with_capacity(n),
            z: Vec::with_capacity(n),
            t: Vec::with_capacity(n),
            intensity: Vec::with_capacity(n),
            scan_angle_deg: Vec::with_capacity(n),
            channel: Vec::with_capacity(n),
        }
    }

    pub(super) fn shrink_to_fit(&mut self) {
        self.x.shrink_to_fit();
        self.y.shrink_to_fit();
        self.z.shrink_to_fit();
        self.t.shrink_to_fit();
        self.intensity.shrink_to_fit();
        self.scan_angle_deg.shrink_to_fit();
        self.channel.shrink_to_fit();
    }

    /// Appends one point: position, time, intensity, scan angle and channel.
    #[allow(clippy::too_many_arguments)]
    pub fn push(&mut self, x: f64, y: f64, z: f64, t: f64, intensity: u16, sa: f32, ch: u8) {
        self.x.push(x);
        self.y.push(y);
        self.z.push(z);
        self.t.push(t);
        self.intensity.push(intensity);
        self.scan_angle_deg.push(sa);
        self.channel.push(ch);
    }

    /// Appends point `i` of `o`.
    pub fn push_from(&mut self, o: &PointColumns, i: usize) {
        self.push(
            o.x[i],
            o.y[i],
            o.z[i],
            o.t[i],
            o.intensity[i],
            o.scan_angle_deg[i],
            o.channel[i],
        );
    }

    /// Appends the points `range` of `o`.
    pub fn extend_from(&mut self, o: &PointColumns, range: std::ops::Range<usize>) {
        self.x.extend_from_slice(&o.x[range.clone()]);
        self.y.extend_from_slice(&o.y[range.clone()]);
        self.z.extend_from_slice(&o.z[range.clone()]);
        self.t.extend_from_slice(&o.t[range.clone()]);
        self.intensity
            .extend_from_slice(&o.intensity[range.clone()]);
        self.scan_angle_deg
            .extend_from_slice(&o.scan_angle_deg[range.clone()]);
        self.channel.extend_from_slice(&o.channel[range]);
    }

    /// Removes the first `n` points.
    pub fn drain_front(&mut self, n: usize) {
        self.keep_range(n.min(self.len())..self.len());
    }

    /// True when the times never decrease.
    pub fn is_time_ordered(&self) -> bool {
        self.t.windows(2).all(|w| w[0] <= w[1])
    }

    /// Whether the scan angle column carries information (not all one value).
    pub(super) fn has_scan_angle(&self) -> bool {
        self.scan_angle_deg
            .first()
            .is_some_and(|&a| self.scan_angle_deg.iter().any(|&b| b != a))
    }

    /// Keeps the points `range` (the ones the trajectory covers: contiguous, as the columns
    /// are sorted by time), in place.
    pub fn keep_range(&mut self, range: std::ops::Range<usize>) {
        fn go<T>(v: &mut Vec<T>, r: &std::ops::Range<usize>) {
            v.truncate(r.end);
            v.drain(..r.start.min(v.len()));
        }
        go(&mut self.x, &range);
        go(&mut self.y, &range);
        go(&mut self.z, &range);
        go(&mut self.t, &range);
        go(&mut self.intensity, &range);
        go(&mut self.scan_angle_deg, &range);
        go(&mut self.channel, &range);
    }
}

/// Appends the `raw` records to `cols`, one column per rayon task, decoding the fields at
/// their LAS offsets (x, y, z at 0, 4, 8; intensity at 12; legacy formats: scan angle rank
/// i8 at 16, GPS time at 20; formats 6–10: scan angle i16 × 0.006° at 18, GPS time at 22).
/// Returns the index within `raw` of the first point whose time is not finite.
pub(super) fn decode_all_parallel(
    raw: &[u8],
    record_len: usize,
    extended: bool,
    tr: &las::Vector<las::Transform>,
    cols: &mut PointColumns,
) -> Option<usize> {
    let n = raw.len() / record_len;
    let base = cols.len();
    let recs = || raw.chunks_exact(record_len);
    let i32_at = |r: &[u8], o: usize| i32::from_le_bytes([r[o], r[o + 1], r[o + 2], r[o + 3]]);
    let gps_at = if extended { 22 } else { 20 };
    cols.x.resize(base + n, 0.0);
    cols.y.resize(base + n, 0.0);
    cols.z.resize(base + n, 0.0);
    cols.t.resize(base + n, 0.0);
    cols.intensity.resize(base + n, 0);
    cols.scan_angle_deg.resize(base + n, 0.0);
    cols.channel.resize(base + n, 0);
    let mut bad_t = None;
    let PointColumns {
        x,
        y,
        z,
        t,
        intensity,
        scan_angle_deg,
        channel,
    } = cols;
    rayon::scope(|s| {
        s.spawn(|_| {
            for (v, r) in x[base..].iter_mut().zip(recs()) {
                *v = tr.x.direct(i32_at(r, 0));
            }
        });
        s.spawn(|_| {
            for (v, r) in y[base..].iter_mut().zip(recs()) {
                *v = tr.y.direct(i32_at(r, 4));
            }
        });
        s.spawn(|_| {
            for (v, r) in z[base..].iter_mut().zip(recs()) {
                *v = tr.z.direct(i32_at(r, 8));
            }
        });
        s.spawn(|_| {
            for (v, r) in intensity[base..].iter_mut().zip(recs()) {
                *v = u16::from_le_bytes([r[12], r[13]]);
            }
            for (v, r) in scan_angle_deg[base..].iter_mut().zip(recs()) {
                *v = if extended {
                    f32::from(i16::from_le_bytes([r[18], r[19]])) * 0.006
                } else {
                    f32::from(r[16] as i8)
                };
            }
            if extended {
                for (v, r) in channel[base..].iter_mut().zip(recs()) {
                    *v = super::scanner::channel_of(r);
                }
            }
        });
        let bad = &mut bad_t;
        s.spawn(move |_| {
            for (k, (v, r)) in t[base..].iter_mut().zip(recs()).enumerate() {
                let mut b = [0u8; 8];
                b.copy_from_slice(&r[gps_at..gps_at + 8]);
                *v = f64::from_le_bytes(b);
                if !v.is_finite() && bad.is_none() {
                    *bad = Some(k);
                }
            }
        });
    });
    bad_t
}
