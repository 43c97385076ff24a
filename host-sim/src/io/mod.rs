//! Everything that touches files: fog-runs records, foreign recordings (import) and
//! output safety. Kept in one place so every command reads and writes the same way.

pub mod import;
pub mod runs;
