//! End-to-end tests of curbtrace live in `tests/tests/`.
