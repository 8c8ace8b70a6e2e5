//! Input parsers. Every error names the file, the line and the reason.

pub mod obj;
pub mod patches;
