//! ik
