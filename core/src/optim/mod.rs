//! General optimisers used by both the identification and the compensators:
//! the Levenberg–Marquardt driver (`lm`, thesis eqs. 2.3–2.4 and ch. 4) and
//! teaching–learning-based optimisation (`tlbo`, thesis ch. 6–7).

pub mod lm;
pub mod tlbo;

pub use tlbo::{TlboResult, TlboSettings};
