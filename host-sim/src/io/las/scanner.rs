//! Which points are one scanner (docs/spec.md §3: "default: all points are one scanner
//! unless the file says otherwise").
//!
//! - Without `--scanner`: in the LAS 1.4 formats 6–10, if the scanner channel (two bits of
//!   the flags byte) takes more than one value, the file says there are several scanners and
//!   reading stops with an error listing the channels, so the user picks one. Otherwise
//!   (legacy formats, or one channel) every point is read. Point source ids are not looked
//!   at by default: in mobile data they usually number drive lines or strips, not scanners.
//! - With `--scanner ID`: in formats 6–10 whose scanner channel is not 0 everywhere, ID is
//!   the scanner channel (0–3); otherwise ID is the point source id.

use super::LasError;
use std::path::Path;

/// How the points were selected (for the summary).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScannerSelection {
    /// Every point (no `--scanner`, at most one scanner channel in the file).
    All,
    /// Points of one LAS 1.4 scanner channel.
    Channel(u8),
    /// Points of one point source id.
    PointSourceId(u16),
}

/// The scanner channel of a raw format 6–10 record: bits 4–5 of the flags byte at 15.
pub(super) fn channel_of(rec: &[u8]) -> u8 {
    (rec[15] >> 4) & 3
}

/// The selection rule applied batch by batch while decoding.
///
/// The rule needs to know whether channels are in use before keeping points, so with
/// `--scanner` on an extended format the first batch decides: if any of its points uses a
/// channel other than 0 the ID is a channel. A file whose first batch is all channel 0 but
/// later batches are not is refused at the end ([`Selector::finish`]).
pub(super) struct Selector {
    scanner: Option<u16>,
    extended: bool,
    selection: Option<ScannerSelection>,
    channels_seen: [bool; 4],
}

impl Selector {
    /// The rule for `--scanner` `scanner` on a file whose format is `extended` (6–10).
    pub fn new(scanner: Option<u16>, extended: bool) -> Self {
        let selection = match (scanner, extended) {
            (None, _) => Some(ScannerSelection::All),
            (Some(id), false) => Some(ScannerSelection::PointSourceId(id)),
            (Some(_), true) => None,
        };
        Self {
            scanner,
            extended,
            selection,
            channels_seen: [false; 4],
        }
    }

    /// Notes the channels of one batch of raw records and returns the selection for it.
    pub fn observe(
        &mut self,
        path: &Path,
        raw: &[u8],
        record_len: usize,
    ) -> Result<ScannerSelection, LasError> {
        if self.extended {
            for rec in raw.chunks_exact(record_len) {
                self.channels_seen[usize::from(channel_of(rec))] = true;
            }
        }
        if let Some(sel) = self.selection {
            return Ok(sel);
        }
        let id = self.scanner.unwrap_or(0);
        let sel = if self.channels_seen[1..].iter().any(|&c| c) {
            ScannerSelection::Channel(u8::try_from(id).ok().filter(|&c| c < 4).ok_or_else(
                || LasError::NoPoints {
                    path: path.to_path_buf(),
                    what: format!("--scanner {id}: scanner channels are 0–3"),
                },
            )?)
        } else {
            ScannerSelection::PointSourceId(id)
        };
        self.selection = Some(sel);
        Ok(sel)
    }

    /// The selection once every point is decoded, or why the file cannot be read as one
    /// scanner.
    pub fn finish(self, path: &Path) -> Result<ScannerSelection, LasError> {
        let channels: Vec<u8> = (0u8..4)
            .filter(|&c| self.channels_seen[usize::from(c)])
            .collect();
        let selection = self.selection.unwrap_or(ScannerSelection::All);
        if self.scanner.is_none() && channels.len() > 1 {
            return Err(LasError::SeveralScanners {
                path: path.to_path_buf(),
                channels,
            });
        }
        if let (Some(id), ScannerSelection::PointSourceId(_)) = (self.scanner, selection) {
            if self.extended && channels.iter().any(|&c| c != 0) {
                // Channels appeared only after the first batch: the ID meant a channel.
                // Re-reading is avoided by refusing clearly instead of silently mixing the
                // two meanings.
                return Err(LasError::NoPoints {
                    path: path.to_path_buf(),
                    what: format!(
                        "--scanner {id}: scanner channels {channels:?} appear only late in the file; cannot tell channel from point source id"
                    ),
                });
            }
            return Ok(ScannerSelection::PointSourceId(id));
        }
        Ok(selection)
    }
}

/// The error for a selection that kept no point.
pub(super) fn nothing_selected(path: &Path, selection: ScannerSelection) -> LasError {
    LasError::NoPoints {
        path: path.to_path_buf(),
        what: match selection {
            ScannerSelection::All => "no points decoded".into(),
            ScannerSelection::Channel(c) => {
                format!("no point of scanner channel {c} (--scanner {c})")
            }
            ScannerSelection::PointSourceId(id) => {
                format!("no point with point source id {id} (--scanner {id})")
            }
        },
    }
}
