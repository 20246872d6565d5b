//! The scanline packet format (`docs/wire-format.md`). SKELETON: filled in by issue 2.
