//! General optimisers used by both the identification and the compensators:
//! teaching–learning-based optimisation (`tlbo`, seed ch. 6–7).

pub mod tlbo;

pub use tlbo::{TlboResult, TlboSettings};
