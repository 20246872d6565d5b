//! The one door to float maths (STYLE.md): call `math::atan2(y, x)`, never methods, so the
//! host build and the target build use the same backend. `libm` (default) gives the same
//! bits everywhere; `micromath` is faster and approximate.
