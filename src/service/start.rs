//! The service state started: on PostgreSQL this replica's job runner
//! (`jobs::shared`) and its listener for the other replicas' changes
//! (`changes.rs`) run beside it. Apart from `state.rs`, which every task
//! holds, so that the state imports none of them.

use super::state::{AppState, ServiceConfig};
use crate::db::Db;

impl AppState {
    /// The state over `db`; on PostgreSQL it starts this replica's job
    /// runner, so it must be made inside a Tokio runtime.
    pub fn new(db: Db, config: ServiceConfig) -> Self {
        let shared = db.backend() == crate::db::Backend::Postgres;
        let state = AppState::build(db, config);
        if shared {
            super::jobs::shared::spawn_runner(&state);
            super::changes::spawn_listener(&state);
        }
        state
    }
}
