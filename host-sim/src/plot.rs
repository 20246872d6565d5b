//! Pictures (issue 5): top views and scanline cross-sections as PNG, drawn with plotters.
