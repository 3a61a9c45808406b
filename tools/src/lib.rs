//! Shared parts of the tools: the SVG charts of `so3fft-bench` and `so3fft-stress`, their
//! CSV files and the progress display of long runs.

pub mod chart;
pub mod csv_out;
pub mod progress;
