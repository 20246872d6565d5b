//! [`KernelParams`]: every parameter of the kernel, with defaults, carried in the stream's
//! config packet as [`CONFIG_WORDS`] little-endian words.

/// Number of 32-bit words of the config packet's parameter block.
pub const CONFIG_WORDS: usize = 16;

/// Why a config block was rejected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum ParamsError {
    /// Word `index` is NaN, infinite or outside its documented range.
    OutOfRange {
        /// Index of the offending word.
        index: u8,
    },
    /// A reserved word is not zero.
    ReservedNotZero {
        /// Index of the offending word.
        index: u8,
    },
}

/// Every parameter of the kernel (and of scanline assembly). SKELETON: fields and defaults
/// are settled by issue 3; each one says where its value comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct KernelParams {
    /// d_b: neighbour distance for the bend angle, metres (§2.3).
    pub d_b_m: f32,
}

impl KernelParams {
    /// The defaults.
    pub const DEFAULT: Self = Self { d_b_m: 0.1 };

    /// A stable 32-bit hash of the parameter words (echoed in every output packet).
    pub fn hash(&self) -> u32 {
        let _ = self;
        0
    }
}

impl Default for KernelParams {
    fn default() -> Self {
        Self::DEFAULT
    }
}
