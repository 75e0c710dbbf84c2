//! A stored job read back for its runner: the command it was queued with,
//! from its `command` column (format 3, or format 2 written before the
//! settings were an object of their own) or, for a job queued before that
//! column existed, from its format-1 columns; then its robot and the rows of
//! its sets.

use super::command::{Format1Options, StartCommand, FORMAT};
use super::prepare::{prepare, Job};
use crate::calibrate::identify::{CalibrationSettings, Method};
use crate::model::RobotModel;
use crate::records::CalibrationRow;
use crate::service::{AppState, ServiceError};
use serde::Deserialize;
use serde_json::Value;

/// A format-2 command: the settings' fields beside the sets, every one
/// required.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Format2Command {
    methods: Vec<Method>,
    identification_set_ids: Option<Vec<i64>>,
    validation_set_ids: Option<Vec<i64>>,
    training_set_ids: Option<Vec<i64>>,
    register: bool,
    max_iterations: usize,
    population: usize,
    generations: usize,
    seed: u64,
    payload_kg: Option<f64>,
}

impl From<Format2Command> for StartCommand {
    fn from(c: Format2Command) -> Self {
        StartCommand {
            identification_set_ids: c.identification_set_ids,
            validation_set_ids: c.validation_set_ids,
            training_set_ids: c.training_set_ids,
            payload_kg: c.payload_kg,
            settings: CalibrationSettings {
                methods: c.methods,
                register: c.register,
                max_iterations: c.max_iterations,
                population: c.population,
                generations: c.generations,
                seed: c.seed,
                ..CalibrationSettings::default()
            },
        }
    }
}

/// A command stored by [`StartCommand::to_stored`], of this format or
/// format 2.
pub(crate) fn command_from_stored(text: &str) -> Result<StartCommand, String> {
    let mut v: Value = serde_json::from_str(text).map_err(|e| e.to_string())?;
    let format = match &mut v {
        Value::Object(map) => map.remove("format").and_then(|f| f.as_u64()),
        _ => None,
    };
    match format {
        Some(FORMAT) => serde_json::from_value(v).map_err(|e| e.to_string()),
        Some(2) => serde_json::from_value::<Format2Command>(v)
            .map(StartCommand::from)
            .map_err(|e| e.to_string()),
        Some(f) => Err(format!(
            "unknown command format {f} (this build reads up to {FORMAT})"
        )),
        None => Err("no command format".into()),
    }
}

/// The command a stored job was queued with: the same sets, methods and
/// options, whichever format stored it.
pub(crate) fn command_of(row: &CalibrationRow) -> Result<StartCommand, ServiceError> {
    let bad = |what: &str| ServiceError::Internal(format!("calibration {}: stored {what}", row.id));
    if let Some(text) = &row.command {
        return command_from_stored(text).map_err(|e| bad(&format!("command: {e}")));
    }
    // Format 1: the columns the API shows.
    let methods = Method::parse_names(&row.methods.0).map_err(|_| bad("methods"))?;
    let o: Format1Options =
        serde_json::from_value(row.options.0.clone()).map_err(|e| bad(&format!("options: {e}")))?;
    Ok(StartCommand {
        identification_set_ids: Some(row.identification_set_ids.0.clone()),
        validation_set_ids: Some(row.validation_set_ids.0.clone()),
        training_set_ids: Some(o.training_set_ids),
        payload_kg: Some(o.payload_kg),
        settings: CalibrationSettings {
            methods,
            register: o.register,
            max_iterations: o.max_iterations,
            population: o.population,
            generations: o.generations,
            seed: o.seed,
            ..CalibrationSettings::default()
        },
    })
}

/// The job of a stored row: its robot, sets and options as stored.
pub(super) async fn load(state: &AppState, robot_id: i64, id: i64) -> Result<Job, ServiceError> {
    let robot = state
        .db()
        .robot(robot_id)
        .await?
        .ok_or_else(|| ServiceError::robot_not_found(robot_id))?;
    let row = state
        .db()
        .calibration(robot_id, id)
        .await?
        .ok_or_else(|| ServiceError::calibration_not_found(robot_id, id))?;
    let nominal = RobotModel::from_json(&robot.model_json)
        .map_err(|e| ServiceError::Internal(format!("stored model of robot {}: {e}", robot.id)))?;
    let cmd = command_of(&row)?;
    let prepared = prepare(state, robot_id, &nominal, &cmd).await?;
    Ok(Job::new(id, robot_id, robot.name, nominal, prepared, None))
}

#[cfg(test)]
mod tests {
    use super::super::command::resolved;
    use super::*;
    use crate::calibrate::compensate::select::Parallelism;
    use crate::calibrate::identify::{CalibrationOptions, CompensatorOptions, LmSettings};
    use crate::optim::TlboSettings;

    #[test]
    fn the_stored_command_reads_back_equal() {
        let c = resolved();
        let text = c.to_stored();
        assert!(text.contains("\"format\":3"), "{text}");
        assert!(text.contains("\"methods\":[\"km\",\"skcm\"]"), "{text}");
        let back = command_from_stored(&text).unwrap();
        assert_eq!(back, c);
        // The payload survives to the bit (0.1 + 0.2 is not 0.3).
        assert_eq!(back.payload_kg.unwrap().to_bits(), (0.1f64 + 0.2).to_bits());
    }

    #[test]
    fn a_stored_command_of_another_format_or_none_is_refused() {
        let text = resolved()
            .to_stored()
            .replace("\"format\":3", "\"format\":4");
        let e = command_from_stored(&text).unwrap_err();
        assert!(e.contains("unknown command format 4"), "{e}");
        let text = resolved().to_stored().replace("\"format\":3,", "");
        assert!(command_from_stored(&text).is_err());
        let text = resolved().to_stored().replace("\"seed\"", "\"sed\"");
        assert!(command_from_stored(&text).is_err());
    }

    /// A format-2 command as the build before format 3 stored it (its JSON
    /// copied from a job's `command` column): it reads to the same sets and
    /// payload, and runs with the options that build ran it with.
    #[test]
    fn a_format_2_command_stored_before_reads_to_the_same_options() {
        let stored = r#"{"format":2,"generations":80,"identification_set_ids":[3,1],"max_iterations":40,"methods":["km","skcm-tlbo"],"payload_kg":0.30000000000000004,"population":20,"register":false,"seed":7,"training_set_ids":[],"validation_set_ids":[2]}"#;
        let c = command_from_stored(stored).unwrap();
        assert_eq!(c.identification_set_ids, Some(vec![3, 1]));
        assert_eq!(c.validation_set_ids, Some(vec![2]));
        assert_eq!(c.training_set_ids, Some(vec![]));
        assert_eq!(c.payload_kg.unwrap().to_bits(), (0.1f64 + 0.2).to_bits());
        assert_eq!(c.method_names(), ["km", "skcm-tlbo"]);
        // What format 2's `calibration_options` built: its fields where they
        // act, the one seed for TLBO and the compensators, defaults elsewhere.
        let d = CalibrationOptions::default();
        let want = CalibrationOptions {
            methods: vec![Method::Km, Method::SkcmTlbo],
            register: false,
            lm: LmSettings {
                max_iterations: 40,
                ..d.lm.clone()
            },
            tlbo: TlboSettings {
                population: 20,
                generations: 80,
                seed: 7,
            },
            compensator: CompensatorOptions {
                seed: 7,
                parallel: Parallelism::default(),
                ..d.compensator.clone()
            },
            ..d
        };
        assert_eq!(c.calibration_options(), want);
        // A format-2 command missing a field it always held is refused.
        let partial = stored.replace("\"population\":20,", "");
        assert!(command_from_stored(&partial).is_err());
    }
}
