//! The HTTP API against a real store, driven in-process through the router
//! (`tower::ServiceExt::oneshot`): a SQLite file in a temporary directory, or
//! with `ROBOCAL_TEST_DATABASE_URL=postgres://…` a new PostgreSQL database
//! per test on that server (`scripts/pg_temp.sh` starts one).
//!
//! Every response is checked against `openapi.yaml`: its status must be
//! documented for the route and method, and a JSON body must validate against
//! the documented schema (JSON Schema 2020-12, via `jsonschema`).
//!
//! One file per theme: `contract` (routes, spec, bad input, keys, paging),
//! `flow` (the quickstart end to end), `sets` (uploads), `solve` (targets CSV
//! in and out), `cell` (tools, work objects, program filtering), `jobs`
//! (progress, cancellation, saturation, races), `record` (sets a version uses,
//! the calibration record, check poses), `checks` (a moved base: the
//! `shifted` status everywhere; capped per-pose errors), `check_reads` (one
//! check by id, the latest check of each listed robot), `roles` (keys with
//! roles, open reads, the console's security headers), `one_answer` (a target
//! solved and filtered, over HTTP and the CLI, gets one configuration),
//! `progress` (an `auto` job polled to its end:
//! a percentage that never goes back, its candidate, fold and time left),
//! `admission` (large requests share one admission), `slow_clients` (header
//! and body timeouts, the connection cap), `exposure` (no open writes on a
//! network by default), `track` (a robot's linear track: fitted, stored,
//! and carrying predictions and solves, over HTTP and the CLI alike; `track_filter`: a program on
//! it filtered; `track_sets`: a robot on a track uploaded one set per station
//! and calibrated over them), `positioner`
//! (a robot's two-axis positioner: fitted, stored, and carrying a targets CSV,
//! over HTTP and the CLI alike; `positioner_touches`: fitted from touches
//! with a stored version and tool), `turntable` (a robot's one-axis
//! turntable: fitted, stored, refitted and deleted, over HTTP and the CLI
//! alike); the harness is `support`.

mod abandoned;
mod admission;
mod beside_track;
mod cell;
mod cell_fit;
mod check_reads;
mod checks;
#[path = "../common/mod.rs"]
mod common;
mod contract;
#[path = "../../core/tests/common/positioner.rs"]
#[allow(dead_code)]
mod core_positioner;
#[path = "../../core/tests/common/track.rs"]
#[allow(dead_code)]
mod core_track;
mod exposure;
mod fit_request;
mod flow;
mod hostile;
#[path = "../common/html_table.rs"]
mod html_table;
mod iso9283;
mod iso9283_report;
mod jobs;
mod migrations;
mod numbers;
mod one_answer;
mod per_reading;
mod plans;
mod positioner;
mod positioner_filter;
mod positioner_touches;
mod predict;
mod progress;
mod record;
mod reregister;
mod roles;
mod sets;
mod slow_clients;
mod solve;
mod spec;
mod stored;
mod stored_jobs;
mod support;
mod track;
mod track_filter;
mod track_sets;
mod turntable;
mod turntable_use;
