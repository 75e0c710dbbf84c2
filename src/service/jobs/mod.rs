//! Calibration jobs, from the command that starts one to the versions it
//! stores. A job keeps one type, [`StartCommand`] (its sets, payload and
//! [`crate::calibrate::identify::CalibrationSettings`]), from the HTTP
//! request to the runner on both backends:
//!
//! - [`command`]: the typed, serialisable start command and its stored forms;
//! - [`prepare`]: the sets of a command by role, their sessions and poses,
//!   read into a [`prepare::Job`];
//! - [`stored`]: a stored job read back (its command in any stored form);
//! - [`runner`]: runs a started job, writes its progress and its outcome;
//! - [`versions`]: what a successful job stores (model versions, summary);
//! - [`local`]: the jobs of this process (SQLite) and their restart;
//! - [`shared`]: the jobs shared by replicas (PostgreSQL): claims, leases,
//!   heartbeats, hand-back on shutdown.
//!
//! Imports run one way: `command` ← `prepare` ← `stored`, `runner` ←
//! `local`, `shared`; nothing here imports `service::calibrations`, which
//! queues jobs through this folder.

pub mod command;
pub mod local;
pub(crate) mod prepare;
pub(crate) mod runner;
pub mod shared;
pub(crate) mod stored;
pub mod versions;

pub use command::StartCommand;
