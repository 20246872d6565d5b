//! The scanline packet format: bytes ↔ packets (`docs/wire-format.md` is the specification).
//!
//! A stream is a concatenation of packets. Every packet starts with the 12-byte header
//! (sync word, version, kind, length, reserved flags, sequence number) and ends with a
//! CRC-32 ([`crc`]) of everything before it. Three kinds follow the header:
//!
//! - **points** ([`PointRecord`], [`PointsRepr`]) — a 64-bit base time and up to
//!   [`MAX_POINTS_PER_PACKET`] point records;
//! - **config** ([`ConfigRepr`]) — the [`CONFIG_WORDS`] parameter words of the kernel;
//! - **output** ([`OutputHeaderRepr`], [`OutputPointRepr`]) — one fragment of the kernel's
//!   result for one scanline;
//! - **candidates** ([`CandidatesRepr`], version 2) — one scanline's nadir and seed
//!   candidates only.
//!
//! The layer follows smoltcp's shape: [`Packet`] is a zero-copy view over bytes whose field
//! offsets live in the private `field` module, the `*Repr` types are checked, owned
//! representations with `parse` and `emit`, and [`StreamEncoder`] writes whole packets and
//! keeps the sequence numbers. [`scan`] finds packets in a byte slice (resynchronising
//! after garbage) for host tools; the ring-buffer path is in [`crate::scanline`].
//!
//! ```
//! use curbtrace_core::wire::{
//!     scan, Packet, PointRecord, PointsRepr, Scan, StreamEncoder, MAX_PACKET_LEN,
//! };
//!
//! let mut enc = StreamEncoder::new();
//! let mut buf = [0u8; MAX_PACKET_LEN];
//! let p = PointRecord { dt_ns: 0, x_m: 1.5, z_m: -2.0, intensity: 300, line_start: true, tag: 7 };
//! let n = enc.encode_points(1_000_000_000, &[p], &mut buf).unwrap();
//! assert_eq!(scan(&buf[..n], true), Scan::Packet { len: n });
//! let packet = Packet::new_checked(&buf[..n]).unwrap();
//! let repr = PointsRepr::parse(&packet).unwrap();
//! assert_eq!((repr.base_time_ns, repr.points[0]), (1_000_000_000, p));
//! // NaN cannot be encoded.
//! let bad = PointRecord { x_m: f32::NAN, ..p };
//! assert!(enc.encode_points(0, &[bad], &mut buf).is_err());
//! ```
//!
//! # Panic contract
//!
//! Nothing in this module panics on any input. Accessors of [`Packet`] read fields with
//! bounds-checked slicing: after [`Packet::new_checked`] has succeeded every field is in
//! bounds; on a view made with [`Packet::new_unchecked`] over a too-short buffer, missing
//! bytes read as zero. There is no `unwrap`, no unchecked indexing and no truncating
//! cast (`try_from` everywhere) in this module.

pub mod crc;
mod encoder;
mod output;
mod points;
mod scan;

pub use encoder::StreamEncoder;
pub use output::{
    CandidatesRepr, OutputColumns, OutputHeaderRepr, OutputPointRepr, OutputPoints,
    CANDIDATES_PACKET_LEN, OUTPUT_HEADER_LEN, OUTPUT_POINT_LEN,
};
pub use points::{PointRecord, PointsRepr, POINT_FLAG_LINE_START, POINT_RECORD_LEN};
pub(crate) use scan::copy_from_two;
pub use scan::{scan, scan_two, GarbageReason, Scan};

/// The two sync bytes that open every packet (`A5 C3`; in little-endian as a `u16`: 0xC3A5).
pub const SYNC: [u8; 2] = [0xA5, 0xC3];
/// The newest format version this code reads and writes. A writer gives each packet the
/// lowest version that expresses it ([`VERSION_1`] unless the packet uses a field of
/// version 2), so a stream without version-2 features is byte for byte a version-1 stream.
pub const VERSION: u8 = 2;
/// The first version, still read.
pub const VERSION_1: u8 = 1;
/// Header flag (version 2): the packet travels on a link that checks its integrity itself
/// (e.g. SPI with its hardware CRC, from the scanner's front end), so its CRC field is zero
/// and not computed. Any other flag bit is reserved.
pub const FLAG_LINK_CHECKED: u16 = 1;
/// Config words a version-1 config packet may set (the rest must be zero in version 1).
pub const CONFIG_WORDS_V1: usize = 10;
/// Length of the common header in bytes.
pub const HEADER_LEN: usize = 12;
/// Length of the trailing CRC in bytes.
pub const CRC_LEN: usize = 4;
/// The smallest possible packet (header and CRC, empty payload): a reader rejects shorter
/// length fields before waiting for the rest.
pub const MIN_PACKET_LEN: usize = HEADER_LEN + CRC_LEN;
/// The largest packet of any kind, in bytes: the payload of one UDP datagram in a
/// 1500-byte Ethernet MTU (1500 − 20 IP − 8 UDP), so an output packet never fragments.
pub const MAX_PACKET_LEN: usize = 1472;
/// Length of the points payload before the records (the 64-bit base time).
pub const POINTS_PREFIX_LEN: usize = 8;
/// The largest number of point records in one points packet. 64 records make a packet of
/// 1304 bytes: a power of two that fits [`MAX_PACKET_LEN`].
pub const MAX_POINTS_PER_PACKET: usize = 64;
/// The largest number of output points in one output packet (1464 bytes).
pub const MAX_OUTPUT_POINTS_PER_PACKET: usize =
    (MAX_PACKET_LEN - HEADER_LEN - OUTPUT_HEADER_LEN - CRC_LEN) / OUTPUT_POINT_LEN;
/// Number of 32-bit words in a config packet's payload. The wire layer carries them
/// opaquely; `kernel::KernelParams` converts parameters to and from them.
pub const CONFIG_WORDS: usize = 16;
/// Length of a config packet (fixed).
pub const CONFIG_PACKET_LEN: usize = HEADER_LEN + 4 * CONFIG_WORDS + CRC_LEN;

const _: () = {
    assert!(
        HEADER_LEN + POINTS_PREFIX_LEN + MAX_POINTS_PER_PACKET * POINT_RECORD_LEN + CRC_LEN
            <= MAX_PACKET_LEN
    );
    assert!(CONFIG_PACKET_LEN <= MAX_PACKET_LEN);
    assert!(MAX_PACKET_LEN <= u16::MAX as usize);
    assert!(MAX_OUTPUT_POINTS_PER_PACKET >= 1);
};

/// Field offsets of the common header and of the fixed parts of each payload (byte ranges
/// from the start of the packet, or of the record for per-record fields).
mod field {
    /// A byte range.
    pub type Field = core::ops::Range<usize>;

    pub const SYNC: Field = 0..2;
    pub const VERSION: usize = 2;
    pub const KIND: usize = 3;
    pub const LENGTH: Field = 4..6;
    pub const FLAGS: Field = 6..8;
    pub const SEQ: Field = 8..12;
    pub const PAYLOAD: usize = 12;

    /// Points payload: base time, then the records.
    pub const BASE_TIME: Field = 12..20;
    pub const RECORDS: usize = 20;

    /// One point record (offsets within the record).
    pub mod point {
        use super::Field;
        pub const DT_NS: Field = 0..4;
        pub const X: Field = 4..8;
        pub const Z: Field = 8..12;
        pub const INTENSITY: Field = 12..14;
        pub const FLAGS: Field = 14..16;
        pub const TAG: Field = 16..20;
    }

    /// Output payload header (offsets from the start of the packet).
    pub mod out {
        use super::Field;
        pub const INDEX: Field = 12..16;
        pub const START_TIME: Field = 16..24;
        pub const PARAMS_HASH: Field = 24..28;
        pub const TRUNCATED: Field = 28..32;
        pub const LINE_LEN: Field = 32..34;
        pub const FIRST: Field = 34..36;
        pub const NADIR: Field = 36..38;
        pub const LEFT: Field = 38..40;
        pub const RIGHT: Field = 40..42;
        pub const KEPT: Field = 42..44;
        pub const IRREGULAR: Field = 44..46;
        pub const NO_NEIGHBOUR: Field = 46..48;
        pub const PEAKS: Field = 48..50;
        /// Reserved (zero) in version 1; points outside the region of interest in 2.
        pub const OUTSIDE: Field = 50..52;
        pub const POINTS: usize = 52;
    }

    /// One output point (offsets within the record).
    pub mod out_point {
        use super::Field;
        pub const TAG: Field = 0..4;
        pub const X_UM: Field = 4..8;
        pub const Z_UM: Field = 8..12;
        pub const RHO_CDEG: Field = 12..14;
        pub const STATUS: usize = 14;
        pub const RESERVED: usize = 15;
    }
}

/// Why bytes were not a valid packet.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum Error {
    /// The buffer holds fewer bytes than the header, or than the length field says.
    Truncated {
        /// Bytes needed.
        needed: usize,
        /// Bytes available.
        available: usize,
    },
    /// The first two bytes are not [`SYNC`].
    BadSync,
    /// The version byte is not one this code reads (1 or [`VERSION`]), or names a
    /// version older than a field the packet uses.
    BadVersion {
        /// The version found.
        version: u8,
    },
    /// The kind byte names no known packet kind.
    BadKind {
        /// The kind found.
        kind: u8,
    },
    /// The length field is outside `MIN_PACKET_LEN..=MAX_PACKET_LEN` or does not fit the
    /// packet's kind (wrong fixed length, or not a whole number of records).
    BadLength {
        /// The length field.
        length: usize,
    },
    /// The stored CRC does not match the bytes.
    Crc {
        /// CRC stored in the packet.
        stored: u32,
        /// CRC computed over the packet.
        computed: u32,
    },
    /// A reserved field or bit is not zero (the format is canonical).
    ReservedNotZero {
        /// Byte offset of the field in the packet.
        offset: usize,
    },
    /// A float field is NaN or infinite.
    NonFinite {
        /// Byte offset of the field in the packet.
        offset: usize,
    },
    /// A field is outside its documented range (e.g. ρ, or an index ≥ the line length).
    OutOfRange {
        /// Byte offset of the field in the packet.
        offset: usize,
    },
    /// The packet is valid but of another kind than the parser asked for.
    WrongKind {
        /// The kind found.
        kind: u8,
    },
}

/// Why a packet could not be encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum EncodeError {
    /// The output buffer is too small.
    BufferTooSmall {
        /// Bytes needed.
        needed: usize,
        /// Bytes available.
        available: usize,
    },
    /// More items than one packet (or the format) can hold.
    TooManyPoints {
        /// Items given.
        count: usize,
        /// The limit.
        max: usize,
    },
    /// A float value is NaN or infinite.
    NonFinite {
        /// Index of the offending item.
        index: usize,
    },
    /// A value does not fit its field (scaled integer out of range, index ≥ line length,
    /// reserved bit requested).
    OutOfRange {
        /// Index of the offending item.
        index: usize,
    },
}

impl core::fmt::Display for Error {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Error::Truncated { needed, available } => write!(
                f,
                "packet truncated: {needed} bytes needed, {available} available"
            ),
            Error::BadSync => write!(f, "packet does not start with the sync bytes A5 C3"),
            Error::BadVersion { version } => write!(
                f,
                "packet has format version {version}, this code reads versions {VERSION_1}..={VERSION} (version 2 for the fields it uses)"
            ),
            Error::BadKind { kind } => write!(f, "packet kind {kind} is not a known kind"),
            Error::BadLength { length } => write!(
                f,
                "packet length field {length} is outside {MIN_PACKET_LEN}..={MAX_PACKET_LEN} \
                 or does not fit the packet's kind"
            ),
            Error::Crc { stored, computed } => write!(
                f,
                "packet CRC mismatch: stored {stored:#010x}, computed {computed:#010x}"
            ),
            Error::ReservedNotZero { offset } => {
                write!(
                    f,
                    "reserved field at byte {offset} of the packet is not zero"
                )
            }
            Error::NonFinite { offset } => {
                write!(
                    f,
                    "float field at byte {offset} of the packet is NaN or infinite"
                )
            }
            Error::OutOfRange { offset } => {
                write!(
                    f,
                    "field at byte {offset} of the packet is out of its range"
                )
            }
            Error::WrongKind { kind } => {
                write!(f, "packet is of kind {kind}, not the kind asked for")
            }
        }
    }
}

impl core::error::Error for Error {}

impl core::fmt::Display for EncodeError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            EncodeError::BufferTooSmall { needed, available } => write!(
                f,
                "output buffer too small: {needed} bytes needed, {available} available"
            ),
            EncodeError::TooManyPoints { count, max } => {
                write!(f, "{count} items do not fit one packet (at most {max})")
            }
            EncodeError::NonFinite { index } => {
                write!(f, "item {index} has a NaN or infinite value")
            }
            EncodeError::OutOfRange { index } => {
                write!(f, "item {index} has a value that does not fit its field")
            }
        }
    }
}

impl core::error::Error for EncodeError {}

/// The kind byte of a packet.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
#[non_exhaustive]
pub enum PacketKind {
    /// Point records (scanner or replay → core).
    Points = 1,
    /// Kernel parameter words (start of stream).
    Config = 2,
    /// One fragment of one scanline's kernel output (core → host).
    Output = 3,
    /// One scanline's nadir and seed candidates only (core → host; version 2).
    Candidates = 4,
}

impl PacketKind {
    /// The first format version that has this kind.
    pub const fn min_version(self) -> u8 {
        match self {
            Self::Candidates => 2,
            _ => VERSION_1,
        }
    }

    /// The last format version that has this kind in this form: a packet takes the lowest
    /// version that expresses it (points packets are the same in both, so always 1).
    pub const fn max_version(self) -> u8 {
        match self {
            Self::Points => VERSION_1,
            _ => VERSION,
        }
    }

    /// The kind for byte `b`, if any.
    pub const fn from_u8(b: u8) -> Option<Self> {
        match b {
            1 => Some(Self::Points),
            2 => Some(Self::Config),
            3 => Some(Self::Output),
            4 => Some(Self::Candidates),
            _ => None,
        }
    }

    /// Whether `length` is a valid total packet length for this kind.
    pub const fn length_ok(self, length: usize) -> bool {
        match self {
            Self::Points => {
                let fixed = HEADER_LEN + POINTS_PREFIX_LEN + CRC_LEN;
                length >= fixed
                    && (length - fixed).is_multiple_of(POINT_RECORD_LEN)
                    && (length - fixed) / POINT_RECORD_LEN <= MAX_POINTS_PER_PACKET
            }
            Self::Config => length == CONFIG_PACKET_LEN,
            Self::Output => {
                let fixed = HEADER_LEN + OUTPUT_HEADER_LEN + CRC_LEN;
                length >= fixed
                    && (length - fixed).is_multiple_of(OUTPUT_POINT_LEN)
                    && (length - fixed) / OUTPUT_POINT_LEN <= MAX_OUTPUT_POINTS_PER_PACKET
            }
            Self::Candidates => length == CANDIDATES_PACKET_LEN,
        }
    }
}

// ---- bounds-checked little-endian field access (never panics) -----------------------------

/// Copies `K` bytes at `at`, zeros where the buffer ends.
#[inline]
fn get_bytes<const K: usize>(buf: &[u8], at: usize) -> [u8; K] {
    let mut out = [0u8; K];
    if let Some(src) = at.checked_add(K).and_then(|end| buf.get(at..end)) {
        out.copy_from_slice(src);
    }
    out
}

#[inline]
fn get_u8(buf: &[u8], at: usize) -> u8 {
    buf.get(at).copied().unwrap_or(0)
}
#[inline]
fn get_u16(buf: &[u8], f: field::Field) -> u16 {
    u16::from_le_bytes(get_bytes(buf, f.start))
}
#[inline]
fn get_u32(buf: &[u8], f: field::Field) -> u32 {
    u32::from_le_bytes(get_bytes(buf, f.start))
}
#[inline]
fn get_u64(buf: &[u8], f: field::Field) -> u64 {
    u64::from_le_bytes(get_bytes(buf, f.start))
}

/// Writes `bytes` at `at` if they fit (callers check the length first).
#[inline]
fn put_bytes(buf: &mut [u8], at: usize, bytes: &[u8]) {
    if let Some(dst) = at
        .checked_add(bytes.len())
        .and_then(|end| buf.get_mut(at..end))
    {
        dst.copy_from_slice(bytes);
    }
}

/// Fills in `length`, computes the CRC over `buf[..length - 4]` and stores it.
fn seal(buf: &mut [u8], length: usize) {
    let body = length.saturating_sub(CRC_LEN);
    let crc = crc::crc32(buf.get(..body).unwrap_or(&[]));
    put_bytes(buf, body, &crc.to_le_bytes());
}

/// Writes the common header with format version `version`.
fn emit_header(buf: &mut [u8], version: u8, kind: PacketKind, length: u16, seq: u32) {
    put_bytes(buf, field::SYNC.start, &SYNC);
    put_bytes(buf, field::VERSION, &[version]);
    put_bytes(buf, field::KIND, &[kind as u8]);
    put_bytes(buf, field::LENGTH.start, &length.to_le_bytes());
    put_bytes(buf, field::FLAGS.start, &0u16.to_le_bytes());
    put_bytes(buf, field::SEQ.start, &seq.to_le_bytes());
}

/// A zero-copy view of one packet over a byte buffer (smoltcp's `Packet<T>`).
#[derive(Clone, Copy, Debug)]
pub struct Packet<T: AsRef<[u8]>> {
    buffer: T,
}

impl<T: AsRef<[u8]>> Packet<T> {
    /// Wraps `buffer` without any check (accessors still never panic; see the module's
    /// panic contract).
    pub const fn new_unchecked(buffer: T) -> Self {
        Self { buffer }
    }

    /// Wraps `buffer` after checking that it starts with [`SYNC`], that its length field is
    /// within `MIN_PACKET_LEN..=MAX_PACKET_LEN` and that the buffer holds that many bytes.
    /// Version, kind, length-for-kind and CRC are checked by [`Packet::check`] and the
    /// reprs' `parse`.
    pub fn new_checked(buffer: T) -> Result<Self, Error> {
        let p = Self::new_unchecked(buffer);
        p.check_len()?;
        Ok(p)
    }

    /// The checks of [`Packet::new_checked`].
    pub fn check_len(&self) -> Result<(), Error> {
        let buf = self.buffer.as_ref();
        if buf.len() < HEADER_LEN {
            return Err(Error::Truncated {
                needed: HEADER_LEN,
                available: buf.len(),
            });
        }
        if self.sync() != SYNC {
            return Err(Error::BadSync);
        }
        let length = self.length();
        if !(MIN_PACKET_LEN..=MAX_PACKET_LEN).contains(&length) {
            return Err(Error::BadLength { length });
        }
        if buf.len() < length {
            return Err(Error::Truncated {
                needed: length,
                available: buf.len(),
            });
        }
        Ok(())
    }

    /// Full validation of the envelope: [`Packet::check_len`], CRC (or, for a
    /// [`FLAG_LINK_CHECKED`] packet, a zero CRC field), version, known kind, length valid
    /// for the kind and zero reserved flags. Returns the kind.
    pub fn check(&self) -> Result<PacketKind, Error> {
        self.check_len()?;
        let stored = self.crc();
        if self.link_checked() {
            if stored != 0 {
                return Err(Error::ReservedNotZero {
                    offset: self.length() - CRC_LEN,
                });
            }
        } else {
            let computed = self.compute_crc();
            if computed != stored {
                return Err(Error::Crc { stored, computed });
            }
        }
        let version = self.version();
        if !(VERSION_1..=VERSION).contains(&version) {
            return Err(Error::BadVersion { version });
        }
        let kind = PacketKind::from_u8(self.kind_raw()).ok_or(Error::BadKind {
            kind: self.kind_raw(),
        })?;
        let flags_v = flags_version(self.flags());
        if !(kind.min_version().max(flags_v)..=kind.max_version().max(flags_v)).contains(&version) {
            return Err(Error::BadVersion { version });
        }
        if !kind.length_ok(self.length()) {
            return Err(Error::BadLength {
                length: self.length(),
            });
        }
        if self.flags() & !FLAG_LINK_CHECKED != 0 {
            return Err(Error::ReservedNotZero {
                offset: field::FLAGS.start,
            });
        }
        Ok(kind)
    }

    /// Whether the packet is a version-2 packet flagged [`FLAG_LINK_CHECKED`] (its CRC is
    /// not computed).
    pub fn link_checked(&self) -> bool {
        self.version() == VERSION && self.flags() & FLAG_LINK_CHECKED != 0
    }

    /// The inner buffer.
    pub fn into_inner(self) -> T {
        self.buffer
    }

    /// The first two bytes.
    pub fn sync(&self) -> [u8; 2] {
        get_bytes(self.buffer.as_ref(), field::SYNC.start)
    }
    /// The version byte.
    pub fn version(&self) -> u8 {
        get_u8(self.buffer.as_ref(), field::VERSION)
    }
    /// The kind byte.
    pub fn kind_raw(&self) -> u8 {
        get_u8(self.buffer.as_ref(), field::KIND)
    }
    /// The kind, if known.
    pub fn kind(&self) -> Option<PacketKind> {
        PacketKind::from_u8(self.kind_raw())
    }
    /// The length field: total bytes of the packet, header and CRC included.
    pub fn length(&self) -> usize {
        usize::from(get_u16(self.buffer.as_ref(), field::LENGTH))
    }
    /// The reserved flags (must be zero).
    pub fn flags(&self) -> u16 {
        get_u16(self.buffer.as_ref(), field::FLAGS)
    }
    /// The sequence number.
    pub fn seq(&self) -> u32 {
        get_u32(self.buffer.as_ref(), field::SEQ)
    }
    /// The bytes between header and CRC (empty if the buffer is too short).
    pub fn payload(&self) -> &[u8] {
        let end = self.length().saturating_sub(CRC_LEN);
        self.buffer.as_ref().get(field::PAYLOAD..end).unwrap_or(&[])
    }
    /// The whole packet as the length field delimits it (empty if the buffer is too short).
    pub fn bytes(&self) -> &[u8] {
        self.buffer.as_ref().get(..self.length()).unwrap_or(&[])
    }
    /// The stored CRC.
    pub fn crc(&self) -> u32 {
        let at = self.length().saturating_sub(CRC_LEN);
        u32::from_le_bytes(get_bytes(self.buffer.as_ref(), at))
    }
    /// The CRC computed over the header and payload.
    pub fn compute_crc(&self) -> u32 {
        let end = self.length().saturating_sub(CRC_LEN);
        crc::crc32(self.buffer.as_ref().get(..end).unwrap_or(&[]))
    }

    /// Points packets: the base time in ns.
    pub fn base_time_ns(&self) -> u64 {
        get_u64(self.buffer.as_ref(), field::BASE_TIME)
    }
    /// Points packets: the number of records the length field implies.
    pub fn point_count(&self) -> usize {
        self.length().saturating_sub(field::RECORDS + CRC_LEN) / POINT_RECORD_LEN
    }
    /// Points packets: the raw bytes of record `i`, if present.
    pub fn point_bytes(&self, i: usize) -> Option<&[u8]> {
        if i >= self.point_count() {
            return None;
        }
        let at = i
            .checked_mul(POINT_RECORD_LEN)?
            .checked_add(field::RECORDS)?;
        self.buffer
            .as_ref()
            .get(at..at.checked_add(POINT_RECORD_LEN)?)
    }
}

/// The lowest format version that carries header flags `flags` (2 for
/// [`FLAG_LINK_CHECKED`]).
pub const fn flags_version(flags: u16) -> u8 {
    if flags & FLAG_LINK_CHECKED != 0 {
        VERSION
    } else {
        VERSION_1
    }
}

/// Marks the packet at the start of `packet` (its length field delimits it) as
/// [`FLAG_LINK_CHECKED`]: version 2, the flag set, the CRC field zero. For a sender whose
/// link checks integrity itself.
pub fn mark_link_checked(packet: &mut [u8]) {
    let length = usize::from(get_u16(packet, field::LENGTH));
    put_bytes(packet, field::VERSION, &[VERSION]);
    put_bytes(packet, field::FLAGS.start, &FLAG_LINK_CHECKED.to_le_bytes());
    put_bytes(packet, length.saturating_sub(CRC_LEN), &[0; CRC_LEN]);
}

/// The lowest format version whose config packet carries `words` (see
/// [`ConfigRepr::version`]).
pub fn config_version(words: &[u32; CONFIG_WORDS]) -> u8 {
    if words.iter().skip(CONFIG_WORDS_V1).all(|&w| w == 0) {
        VERSION_1
    } else {
        VERSION
    }
}

/// The parameter words of a config packet.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ConfigRepr {
    /// Opaque to the wire layer; `kernel::KernelParams` gives them meaning.
    pub words: [u32; CONFIG_WORDS],
}

impl ConfigRepr {
    /// Parses a config packet (full check, CRC included).
    pub fn parse<T: AsRef<[u8]>>(packet: &Packet<T>) -> Result<Self, Error> {
        let kind = packet.check()?;
        if kind != PacketKind::Config {
            return Err(Error::WrongKind { kind: kind as u8 });
        }
        let mut words = [0u32; CONFIG_WORDS];
        let p = packet.payload();
        for (w, chunk) in words.iter_mut().zip(p.chunks_exact(4)) {
            *w = u32::from_le_bytes(get_bytes(chunk, 0));
        }
        let repr = Self { words };
        if packet.version() != repr.version().max(flags_version(packet.flags())) {
            return Err(Error::BadVersion {
                version: packet.version(),
            });
        }
        Ok(repr)
    }

    /// The lowest format version that carries these words: 1 when the words of version 2
    /// (from [`CONFIG_WORDS_V1`] on) are all zero, else 2.
    pub fn version(&self) -> u8 {
        config_version(&self.words)
    }

    /// Writes the packet with sequence number `seq` into `out`; returns its length.
    pub fn emit(&self, seq: u32, out: &mut [u8]) -> Result<usize, EncodeError> {
        let len = CONFIG_PACKET_LEN;
        if out.len() < len {
            return Err(EncodeError::BufferTooSmall {
                needed: len,
                available: out.len(),
            });
        }
        let len16 = u16::try_from(len).map_err(|_| EncodeError::OutOfRange { index: 0 })?;
        emit_header(out, self.version(), PacketKind::Config, len16, seq);
        for (i, w) in self.words.iter().enumerate() {
            put_bytes(out, field::PAYLOAD + 4 * i, &w.to_le_bytes());
        }
        seal(out, len);
        Ok(len)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use proptest::prelude::*;

    /// A config packet, byte by byte (see `docs/wire-format.md`).
    fn golden_config() -> [u8; CONFIG_PACKET_LEN] {
        let mut g = [0u8; CONFIG_PACKET_LEN];
        g[..12].copy_from_slice(&[
            0xA5,
            0xC3,
            0x02, // version 2: words 10–15 are not zero
            0x02,
            CONFIG_PACKET_LEN as u8,
            0x00,
            0x00,
            0x00,
            7,
            0,
            0,
            0,
        ]);
        for i in 0..CONFIG_WORDS {
            g[12 + 4 * i..16 + 4 * i].copy_from_slice(&(i as u32 * 0x0101_0101).to_le_bytes());
        }
        let crc = crc::crc32_bytewise(&g[..CONFIG_PACKET_LEN - 4]);
        g[CONFIG_PACKET_LEN - 4..].copy_from_slice(&crc.to_le_bytes());
        g
    }

    /// The messages a user reads are sentences with the numbers of the case.
    #[test]
    fn error_messages() {
        use std::string::ToString;
        let cases: [(Error, &str); 10] = [
            (
                Error::Truncated {
                    needed: 80,
                    available: 12,
                },
                "packet truncated: 80 bytes needed, 12 available",
            ),
            (
                Error::BadSync,
                "packet does not start with the sync bytes A5 C3",
            ),
            (
                Error::BadVersion { version: 3 },
                "packet has format version 3, this code reads versions 1..=2 (version 2 for the fields it uses)",
            ),
            (
                Error::BadKind { kind: 9 },
                "packet kind 9 is not a known kind",
            ),
            (
                Error::BadLength { length: 3 },
                "packet length field 3 is outside 16..=1472 or does not fit the packet's kind",
            ),
            (
                Error::Crc {
                    stored: 0xdead_beef,
                    computed: 0x1234,
                },
                "packet CRC mismatch: stored 0xdeadbeef, computed 0x00001234",
            ),
            (
                Error::ReservedNotZero { offset: 6 },
                "reserved field at byte 6 of the packet is not zero",
            ),
            (
                Error::NonFinite { offset: 24 },
                "float field at byte 24 of the packet is NaN or infinite",
            ),
            (
                Error::OutOfRange { offset: 64 },
                "field at byte 64 of the packet is out of its range",
            ),
            (
                Error::WrongKind { kind: 2 },
                "packet is of kind 2, not the kind asked for",
            ),
        ];
        for (e, want) in cases {
            assert_eq!(e.to_string(), want);
        }
        let cases: [(EncodeError, &str); 4] = [
            (
                EncodeError::BufferTooSmall {
                    needed: 80,
                    available: 10,
                },
                "output buffer too small: 80 bytes needed, 10 available",
            ),
            (
                EncodeError::TooManyPoints { count: 65, max: 64 },
                "65 items do not fit one packet (at most 64)",
            ),
            (
                EncodeError::NonFinite { index: 3 },
                "item 3 has a NaN or infinite value",
            ),
            (
                EncodeError::OutOfRange { index: 4 },
                "item 4 has a value that does not fit its field",
            ),
        ];
        for (e, want) in cases {
            assert_eq!(e.to_string(), want);
        }
    }

    #[test]
    fn config_golden() {
        assert_eq!(CONFIG_PACKET_LEN, 80);
        let g = golden_config();
        let p = Packet::new_checked(&g[..]).unwrap();
        assert_eq!(p.kind(), Some(PacketKind::Config));
        assert_eq!(p.seq(), 7);
        assert_eq!(p.length(), 80);
        let r = ConfigRepr::parse(&p).unwrap();
        assert_eq!(r.words[3], 0x0303_0303);
        let mut out = [0u8; 100];
        assert_eq!(r.emit(7, &mut out), Ok(80));
        assert_eq!(&out[..80], &g[..]);
    }

    #[test]
    fn header_checks() {
        let g = golden_config();
        assert_eq!(
            Packet::new_checked(&g[..11]).unwrap_err(),
            Error::Truncated {
                needed: 12,
                available: 11
            }
        );
        assert_eq!(
            Packet::new_checked(&g[..CONFIG_PACKET_LEN - 1]).unwrap_err(),
            Error::Truncated {
                needed: CONFIG_PACKET_LEN,
                available: CONFIG_PACKET_LEN - 1
            }
        );
        let mut b = g;
        b[0] = 0;
        assert_eq!(Packet::new_checked(&b[..]).unwrap_err(), Error::BadSync);
        let mut b = g;
        b[4] = 15; // below MIN_PACKET_LEN
        assert_eq!(
            Packet::new_checked(&b[..]).unwrap_err(),
            Error::BadLength { length: 15 }
        );
        let mut b = g;
        b[20] ^= 1;
        assert!(matches!(
            ConfigRepr::parse(&Packet::new_unchecked(&b[..])),
            Err(Error::Crc { .. })
        ));
        // Valid CRC but a reserved flag set: rejected (canonical format).
        let mut b = g;
        b[6] = 2;
        let crc = crc::crc32(&b[..CONFIG_PACKET_LEN - 4]);
        b[CONFIG_PACKET_LEN - 4..].copy_from_slice(&crc.to_le_bytes());
        assert_eq!(
            ConfigRepr::parse(&Packet::new_unchecked(&b[..])),
            Err(Error::ReservedNotZero { offset: 6 })
        );
        // Version 3 with a valid CRC.
        let mut b = g;
        b[2] = 3;
        let crc = crc::crc32(&b[..CONFIG_PACKET_LEN - 4]);
        b[CONFIG_PACKET_LEN - 4..].copy_from_slice(&crc.to_le_bytes());
        assert_eq!(
            ConfigRepr::parse(&Packet::new_unchecked(&b[..])),
            Err(Error::BadVersion { version: 3 })
        );
        // The golden words use version 2's words: labelled version 1 they are rejected.
        let mut b = g;
        b[2] = 1;
        let crc = crc::crc32(&b[..CONFIG_PACKET_LEN - 4]);
        b[CONFIG_PACKET_LEN - 4..].copy_from_slice(&crc.to_le_bytes());
        assert_eq!(
            ConfigRepr::parse(&Packet::new_unchecked(&b[..])),
            Err(Error::BadVersion { version: 1 })
        );
    }

    #[test]
    fn accessors_never_panic_on_short_buffers() {
        for n in 0..20 {
            let b = [0xA5u8; 20];
            let p = Packet::new_unchecked(&b[..n]);
            let _ = (
                p.seq(),
                p.payload(),
                p.crc(),
                p.compute_crc(),
                p.base_time_ns(),
            );
            let _ = (p.point_count(), p.point_bytes(0), p.check());
        }
    }

    proptest! {
        #[test]
        fn config_roundtrip(v in proptest::collection::vec(any::<u32>(), CONFIG_WORDS), seq in any::<u32>()) {
            let r = ConfigRepr { words: v.try_into().unwrap() };
            let mut out = [0u8; CONFIG_PACKET_LEN];
            prop_assert_eq!(r.emit(seq, &mut out), Ok(CONFIG_PACKET_LEN));
            let p = Packet::new_checked(&out[..]).unwrap();
            prop_assert_eq!(p.seq(), seq);
            prop_assert_eq!(ConfigRepr::parse(&p), Ok(r));
        }

        /// emit ∘ parse is the identity on canonical bytes: any mutation that still parses
        /// re-emits to the same bytes.
        #[test]
        fn config_canonical(v in proptest::collection::vec(any::<u32>(), CONFIG_WORDS), at in 0usize..CONFIG_PACKET_LEN - 4, val in any::<u8>()) {
            let mut b = [0u8; CONFIG_PACKET_LEN];
            ConfigRepr { words: v.try_into().unwrap() }.emit(1, &mut b).unwrap();
            b[at] = val;
            let crc = crc::crc32(&b[..CONFIG_PACKET_LEN - 4]);
            b[CONFIG_PACKET_LEN - 4..].copy_from_slice(&crc.to_le_bytes());
            let p = Packet::new_unchecked(&b[..]);
            if let Ok(r) = ConfigRepr::parse(&p) {
                let mut again = [0u8; CONFIG_PACKET_LEN];
                r.emit(p.seq(), &mut again).unwrap();
                prop_assert_eq!(&again[..], &b[..]);
            }
        }
    }
}
