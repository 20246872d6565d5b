//! [`Sweep`]: one revolution of a spinning multi-beam lidar in the sensor's own frame, as
//! the frame readers ([`super::kitti`], [`super::nuscenes`], [`super::pcd`]) return it.
//!
//! Conventions (docs/frames.md): right-handed, metres, the sensor's optical centre at the
//! origin, **x ahead, y left, z up** (a reader whose format uses other axes turns them into
//! these). Every point carries the ring (laser) it came from, numbered 0..`rings` from the
//! lowest elevation angle to the highest where the format says so (nuScenes, Velodyne's ROS
//! driver), or in the file's own order of lasers (KITTI: recovered from the stored order).

use std::path::Path;

/// Which file format a sweep came from (it names the sensor the format implies).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SweepFormat {
    /// KITTI raw or odometry `.bin`: Velodyne HDL-64E, 10 Hz.
    Kitti,
    /// nuScenes `.pcd.bin` of `LIDAR_TOP`: Velodyne HDL-32E, 20 Hz.
    NuScenes,
    /// PCD (Point Cloud Library) with a ring field: sensor unknown, told by its ring count.
    Pcd,
}

impl SweepFormat {
    /// The name used on the command line and in outputs.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Kitti => "kitti",
            Self::NuScenes => "nuscenes",
            Self::Pcd => "pcd",
        }
    }
}

/// One sweep as columns (index `i` is the same point in every column).
#[derive(Clone, Debug, PartialEq)]
pub struct Sweep {
    /// Format the sweep was read from.
    pub format: SweepFormat,
    /// x (ahead), metres.
    pub x: Vec<f32>,
    /// y (left), metres.
    pub y: Vec<f32>,
    /// z (up), metres.
    pub z: Vec<f32>,
    /// Intensity or reflectance as the file stores it (KITTI 0–1, nuScenes 0–255).
    pub intensity: Vec<f32>,
    /// Ring (laser) of each point, < `rings`.
    pub ring: Vec<u16>,
    /// Number of rings of the sensor (at least 1 + the largest ring in `ring`).
    pub rings: u16,
    /// Points dropped while reading because a coordinate was NaN or infinite.
    pub dropped_non_finite: u64,
}

impl Sweep {
    /// An empty sweep of `format` with room for `n` points.
    pub fn with_capacity(format: SweepFormat, n: usize) -> Self {
        Self {
            format,
            x: Vec::with_capacity(n),
            y: Vec::with_capacity(n),
            z: Vec::with_capacity(n),
            intensity: Vec::with_capacity(n),
            ring: Vec::with_capacity(n),
            rings: 0,
            dropped_non_finite: 0,
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether the sweep holds no point.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Appends a point, or counts it as dropped when a coordinate is not finite.
    pub fn push(&mut self, x: f32, y: f32, z: f32, intensity: f32, ring: u16) {
        if !(x.is_finite() && y.is_finite() && z.is_finite()) {
            self.dropped_non_finite += 1;
            return;
        }
        self.x.push(x);
        self.y.push(y);
        self.z.push(z);
        self.intensity.push(intensity);
        self.ring.push(ring);
        self.rings = self.rings.max(ring.saturating_add(1));
    }
}

/// Why a frame file could not be read. Every message names the file.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// The file could not be opened or read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// The file's content does not fit its format.
    #[error("{path}: {reason}")]
    Format {
        /// The file.
        path: String,
        /// What is wrong, in one sentence.
        reason: String,
    },
}

impl SweepError {
    /// A format error for `path`.
    pub fn format(path: &Path, reason: impl Into<String>) -> Self {
        Self::Format {
            path: path.display().to_string(),
            reason: reason.into(),
        }
    }

    /// An I/O error for `path`.
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Self::Io {
            path: path.display().to_string(),
            source,
        }
    }
}

/// Reads a whole file, naming it in the error.
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>, SweepError> {
    std::fs::read(path).map_err(|e| SweepError::io(path, e))
}

/// The `k`-th little-endian `f32` of a record.
#[inline]
pub(crate) fn f32_at(rec: &[u8], k: usize) -> f32 {
    f32::from_le_bytes([rec[4 * k], rec[4 * k + 1], rec[4 * k + 2], rec[4 * k + 3]])
}
