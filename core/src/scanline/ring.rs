//! A fixed-capacity byte ring. SKELETON: filled in by issue 2.
