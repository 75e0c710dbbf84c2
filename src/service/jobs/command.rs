//! The start command of a calibration job: the methods to run, the sets of
//! each role and every solver option, typed. The HTTP layer builds it once
//! from the request; the service resolves its set choice and default payload
//! when it queues the job ([`StartCommand::resolved`]) and stores that
//! command as it is (format [`FORMAT`]); the runner of this process and a
//! PostgreSQL replica run the stored command unchanged.
//!
//! Stored forms: format 2 is the command's JSON under `"format": 2` in the
//! job's `command` column. Format 1 (jobs queued before the column existed)
//! is the columns `methods`, `identification_set_ids`, `validation_set_ids`
//! and `options` ([`Format1Options`]), which every job still writes because
//! the API shows them; [`super::stored`] reads either.

use crate::calibrate::identify::{CalibrationOptions, CompensatorOptions, LmSettings, Method};
use crate::optim::TlboSettings;
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// The stored format this build writes.
pub const FORMAT: u64 = 2;

/// A calibration to start: methods, data and solver settings, checked by the caller.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StartCommand {
    pub methods: Vec<Method>,
    /// Sets that identify the model; `None`: every set with role identification.
    pub identification_set_ids: Option<Vec<i64>>,
    /// Sets that validate; `None`: every set with role validation.
    pub validation_set_ids: Option<Vec<i64>>,
    /// Sets that train the compensators (Q2); `None`: every set with role
    /// training. Without any, compensators train on the identification sets.
    pub training_set_ids: Option<Vec<i64>>,
    /// Register the tracker frame per session before fitting.
    pub register: bool,
    pub max_iterations: usize,
    pub population: usize,
    pub generations: usize,
    /// Seed of the randomised methods.
    pub seed: u64,
    /// Payload [kg] for sets that declare none (default: the model's).
    pub payload_kg: Option<f64>,
}

/// The `options` column of a job (format 1, and what the API shows): the
/// command's options with its training sets and payload resolved. The fields
/// are in the order the column has always been written in.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Format1Options {
    pub training_set_ids: Vec<i64>,
    pub seed: u64,
    pub population: usize,
    pub generations: usize,
    pub max_iterations: usize,
    pub register: bool,
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

    /// The solver options of the command (the core's defaults otherwise).
    pub fn calibration_options(&self) -> CalibrationOptions {
        let defaults = CalibrationOptions::default();
        CalibrationOptions {
            methods: self.methods.clone(),
            register: self.register,
            lm: LmSettings {
                max_iterations: self.max_iterations,
                ..defaults.lm.clone()
            },
            tlbo: TlboSettings {
                population: self.population,
                generations: self.generations,
                seed: self.seed,
            },
            compensator: CompensatorOptions {
                seed: self.seed,
                ..defaults.compensator.clone()
            },
            ..defaults
        }
    }

    /// The method names, in the command's order (the `methods` column).
    pub fn method_names(&self) -> Vec<String> {
        self.methods.iter().map(|m| m.name().to_string()).collect()
    }

    /// The `options` column of a resolved command; `None` when the command
    /// is not resolved (no training sets or payload chosen).
    pub fn format1_options(&self) -> Option<Format1Options> {
        Some(Format1Options {
            training_set_ids: self.training_set_ids.clone()?,
            seed: self.seed,
            population: self.population,
            generations: self.generations,
            max_iterations: self.max_iterations,
            register: self.register,
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

    /// A command stored by [`StartCommand::to_stored`] (of this or an
    /// earlier format that has a document).
    pub fn from_stored(text: &str) -> Result<Self, String> {
        let mut v: Value = serde_json::from_str(text).map_err(|e| e.to_string())?;
        let format = match &mut v {
            Value::Object(map) => map.remove("format").and_then(|f| f.as_u64()),
            _ => None,
        };
        match format {
            Some(FORMAT) => serde_json::from_value(v).map_err(|e| e.to_string()),
            Some(f) => Err(format!(
                "unknown command format {f} (this build reads up to {FORMAT})"
            )),
            None => Err("no command format".into()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn resolved() -> StartCommand {
        StartCommand {
            methods: vec![Method::Km, Method::Skcm],
            identification_set_ids: None,
            validation_set_ids: None,
            training_set_ids: None,
            register: true,
            max_iterations: 100,
            population: 50,
            generations: 100,
            seed: 7,
            payload_kg: None,
        }
        .resolved(vec![3, 1], vec![2], vec![], 0.1 + 0.2)
    }

    #[test]
    fn the_stored_command_reads_back_equal() {
        let c = resolved();
        let text = c.to_stored();
        assert!(text.contains("\"format\":2"), "{text}");
        assert!(text.contains("\"methods\":[\"km\",\"skcm\"]"), "{text}");
        let back = StartCommand::from_stored(&text).unwrap();
        assert_eq!(back, c);
        // The payload survives to the bit (0.1 + 0.2 is not 0.3).
        assert_eq!(back.payload_kg.unwrap().to_bits(), (0.1f64 + 0.2).to_bits());
    }

    #[test]
    fn a_stored_command_of_another_format_or_none_is_refused() {
        let text = resolved()
            .to_stored()
            .replace("\"format\":2", "\"format\":3");
        let e = StartCommand::from_stored(&text).unwrap_err();
        assert!(e.contains("unknown command format 3"), "{e}");
        let text = resolved().to_stored().replace("\"format\":2,", "");
        assert!(StartCommand::from_stored(&text).is_err());
        let text = resolved().to_stored().replace("\"seed\"", "\"sed\"");
        assert!(StartCommand::from_stored(&text).is_err());
    }

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
