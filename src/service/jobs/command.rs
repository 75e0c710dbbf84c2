//! The start command of a calibration job: the sets of each role, the
//! payload of sets that declare none, and the calibration's settings
//! ([`CalibrationSettings`], the one type the HTTP request and the command
//! line convert into as well). The HTTP layer builds it once from the
//! request; the service resolves its set choice and default payload when it
//! queues the job ([`StartCommand::resolved`]) and stores that command as it
//! is (format [`FORMAT`]); the runner of this process and a PostgreSQL
//! replica run the stored command unchanged.
//!
//! Stored forms: format 3 is the command's JSON under `"format": 3` in the
//! job's `command` column, the settings an object of their own
//! (`"settings": {…}`). Format 2 held the settings' fields beside the sets;
//! format 1 (jobs queued before the column existed) is the columns
//! `methods`, `identification_set_ids`, `validation_set_ids` and `options`
//! ([`Format1Options`]), which every job still writes because the API shows
//! them. [`super::stored`] reads all three.

use crate::calibrate::compensate::select::Parallelism;
use crate::calibrate::identify::{CalibrationOptions, CalibrationSettings};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// The stored format this build writes.
pub const FORMAT: u64 = 3;

/// A calibration to start: its data and its settings, checked by the caller.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StartCommand {
    /// Sets that identify the model; `None`: every set with role identification.
    pub identification_set_ids: Option<Vec<i64>>,
    /// Sets that validate; `None`: every set with role validation.
    pub validation_set_ids: Option<Vec<i64>>,
    /// Sets that train the compensators (Q2); `None`: every set with role
    /// training. Without any, compensators train on the identification sets.
    pub training_set_ids: Option<Vec<i64>>,
    /// Payload [kg] for sets that declare none (default: the model's).
    pub payload_kg: Option<f64>,
    /// The methods and their settings.
    pub settings: CalibrationSettings,
}

/// The `options` column of a job (format 1, and what the API shows): the
/// command's options with its training sets and payload resolved. The fields
/// are in the order the column has always been written in.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Format1Options {
    /// Ids of the sets that train the compensators (empty: they train on the identification sets).
    pub training_set_ids: Vec<i64>,
    /// Seed of every random choice (TLBO, compensator training).
    pub seed: u64,
    /// TLBO population (skcm-tlbo).
    pub population: usize,
    /// TLBO generations (skcm-tlbo).
    pub generations: usize,
    /// Levenberg–Marquardt iteration limit.
    pub max_iterations: usize,
    /// Whether the tracker frame is registered in closed form first.
    pub register: bool,
    /// Payload of rows and sets that give none [kg].
    pub payload_kg: f64,
}

impl StartCommand {
    /// The same command with its sets and payload fixed: `ident`, `valid`
    /// and `train` are the ids the job reads, `payload_kg` the payload of
    /// sets that declare none.
    pub fn resolved(
        &self,
        ident: Vec<i64>,
        valid: Vec<i64>,
        train: Vec<i64>,
        payload_kg: f64,
    ) -> Self {
        StartCommand {
            identification_set_ids: Some(ident),
            validation_set_ids: Some(valid),
            training_set_ids: Some(train),
            payload_kg: Some(payload_kg),
            ..self.clone()
        }
    }

    /// The options the job runs with ([`CalibrationSettings::options`]);
    /// the runner sets the threads of its share of the cores.
    pub fn calibration_options(&self) -> CalibrationOptions {
        self.settings.options(Parallelism::default())
    }

    /// The method names, in the command's order (the `methods` column).
    pub fn method_names(&self) -> Vec<String> {
        let methods = &self.settings.methods;
        methods.iter().map(|m| m.name().to_string()).collect()
    }

    /// The `options` column of a resolved command; `None` when the command
    /// is not resolved (no training sets or payload chosen).
    pub fn format1_options(&self) -> Option<Format1Options> {
        let s = &self.settings;
        Some(Format1Options {
            training_set_ids: self.training_set_ids.clone()?,
            seed: s.seed,
            population: s.population,
            generations: s.generations,
            max_iterations: s.max_iterations,
            register: s.register,
            payload_kg: self.payload_kg?,
        })
    }

    /// The stored form: the command's JSON with `"format": FORMAT`.
    pub fn to_stored(&self) -> String {
        let mut v = serde_json::to_value(self).expect("a command serialises");
        if let Value::Object(map) = &mut v {
            map.insert("format".into(), FORMAT.into());
        }
        v.to_string()
    }
}

/// A resolved command the tests of the command and of its stored form share:
/// two methods, seed 7, a payload that is not a short decimal (0.1 + 0.2).
#[cfg(test)]
pub(super) fn resolved() -> StartCommand {
    use crate::calibrate::identify::Method;
    StartCommand {
        identification_set_ids: None,
        validation_set_ids: None,
        training_set_ids: None,
        payload_kg: None,
        settings: CalibrationSettings {
            methods: vec![Method::Km, Method::Skcm],
            seed: 7,
            ..CalibrationSettings::default()
        },
    }
    .resolved(vec![3, 1], vec![2], vec![], 0.1 + 0.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_options_column_has_the_keys_it_always_had() {
        let v = serde_json::to_value(resolved().format1_options().unwrap()).unwrap();
        let keys: Vec<&String> = v.as_object().unwrap().keys().collect();
        let mut want = [
            "generations",
            "max_iterations",
            "payload_kg",
            "population",
            "register",
            "seed",
            "training_set_ids",
        ];
        want.sort_unstable();
        let mut keys: Vec<&str> = keys.iter().map(|k| k.as_str()).collect();
        keys.sort_unstable();
        assert_eq!(keys, want);
        assert_eq!(v["seed"], 7);
        assert_eq!(v["training_set_ids"], serde_json::json!([]));
        // Unresolved, there is no options column to write.
        let mut c = resolved();
        c.training_set_ids = None;
        assert!(c.format1_options().is_none());
    }
}
