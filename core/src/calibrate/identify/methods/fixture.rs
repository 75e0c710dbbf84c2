//! A calibration context on simulated data for the methods' unit tests: a
//! UR5 whose joint 2 has a one-harmonic angle error of 0.2 mrad over its
//! whole travel (what KM lacks and the joint maps model), measured in
//! position with ±0.02 mm uniform noise [m inside, mm in figures]; half the
//! poses identify, half train. Gravity is declared absent, so `auto` weighs
//! KM alone with its joint maps.

use super::context::Context;
use super::{Method, MethodFailure};
use crate::calibrate::identify::options::CalibrationOptions;
use crate::measure::Measurement;
use crate::model::kinematics::{chain, fk, Chain};
use crate::model::{preset, JointMap, JointMaps, ParamId, ParamKind, RobotModel};
use crate::sim::random_configurations;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The simulated poses and what a context borrows.
pub(super) struct Fixture {
    pub nominal: RobotModel,
    ident: Vec<Measurement>,
    training: Vec<Measurement>,
    chains: Vec<Chain>,
}

impl Fixture {
    /// `n` poses drawn from `ChaCha8Rng(11)` (module docs).
    pub(crate) fn measured(n: usize) -> Fixture {
        let nominal = preset("ur5").unwrap();
        let mut map = JointMap::zero(1, [-7.0, 7.0], 0.1);
        map.cos[0] = 2e-4;
        map.sin[0] = -1e-4;
        let mut joints = vec![None; nominal.dof()];
        joints[1] = Some(map);
        let maps = JointMaps { joints };
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let qs = random_configurations(&nominal, n, &mut rng);
        let mut data: Vec<Measurement> = qs
            .into_iter()
            .map(|q| {
                let mut turned = q.clone();
                maps.add_to(&q, &mut turned);
                let p = fk(&nominal, &turned).unwrap().p;
                let noise = nalgebra::Vector3::from_fn(|_, _| rng.gen_range(-2e-5..2e-5));
                Measurement {
                    q,
                    position: p + noise,
                    orientation: None,
                    payload_mass: 0.0,
                    session: 0,
                    std: None,
                }
            })
            .collect();
        let training = data.split_off(n / 2);
        let chains = data
            .iter()
            .map(|m| chain(&nominal, &m.q).unwrap())
            .collect();
        Fixture {
            nominal,
            ident: data,
            training,
            chains,
        }
    }

    /// `auto` weighing `km-maps`, the folds dealt from `seed`, the maps
    /// choosing among 1–4 harmonics with one ridge.
    pub(crate) fn options(&self, seed: u64) -> CalibrationOptions {
        let mut opts = CalibrationOptions::default();
        opts.compensator.seed = seed;
        opts.compensator.auto_candidates = vec![Method::KmMaps];
        opts.joint_maps.harmonics = vec![1, 2, 3, 4];
        opts.joint_maps.ridge = vec![1e-6];
        opts
    }

    /// The context of these poses under `opts`: KM identifies the joint
    /// offsets of joints 2–5.
    pub(crate) fn context<'a>(&'a self, opts: &'a CalibrationOptions) -> Context<'a> {
        Context {
            nominal: &self.nominal,
            start: self.nominal.clone(),
            ident: &self.ident,
            ident_chains: &self.chains,
            valid: &[],
            training: &self.training,
            sessions: 1,
            kept_geo: (1..5).map(|k| ParamId::new(ParamKind::Theta, k)).collect(),
            kept_c: Vec::new(),
            gravity: Some(MethodFailure::NoGravityTorque),
            opts,
        }
    }
}
