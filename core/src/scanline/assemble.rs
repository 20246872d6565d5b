//! Scanline assembly (SPEC §2). SKELETON: filled in by issue 2.
