//! The measurement CSV format (DESIGN "Measurement CSV"); see `parse` and `write`.
