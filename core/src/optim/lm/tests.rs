use super::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The predicted decrease against its definition `‖r‖² − ‖r − J·d‖²`,
/// computed directly, on random tall systems and steps.
#[test]
fn predicted_decrease_is_the_linear_models_decrease() {
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    for (m, n) in [(30, 4), (300, 25), (7, 7)] {
        let j = DMatrix::from_fn(m, n, |_, _| rng.gen_range(-1.0..1.0));
        let r = DVector::from_fn(m, |_, _| rng.gen_range(-1.0..1.0));
        let d = DVector::from_fn(n, |_, _| rng.gen_range(-0.5..0.5));
        let direct = r.norm_squared() - (&r - &j * &d).norm_squared();
        let p = predicted_decrease(&j.tr_mul(&j), &j.tr_mul(&r), &d);
        assert!(
            (p - direct).abs() <= 1e-12 * r.norm_squared(),
            "{p} vs {direct}"
        );
    }
}

/// `r(x) = t − f(x)` for the model `f(x)_i = x₀·exp(x₁·s_i) + x₂` (the
/// Jacobian in closed form), with an optional box and a hook that stops
/// after `stop_after` accepted steps.
struct Exponential {
    s: Vec<f64>,
    t: Vec<f64>,
    x: Vec<f64>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    bounded: bool,
    r: DVector<f64>,
    j: DMatrix<f64>,
    next: Option<(Vec<f64>, f64)>,
    accepted: Vec<f64>,
    stop_after: usize,
}

impl Exponential {
    fn new(truth: [f64; 3], start: [f64; 3], noise: f64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let s: Vec<f64> = (0..40).map(|i| i as f64 / 20.0).collect();
        let t = s
            .iter()
            .map(|s| truth[0] * (truth[1] * s).exp() + truth[2] + noise * rng.gen_range(-1.0..1.0))
            .collect();
        Exponential {
            s,
            t,
            x: start.to_vec(),
            lower: vec![f64::NEG_INFINITY; 3],
            upper: vec![f64::INFINITY; 3],
            bounded: false,
            r: DVector::zeros(40),
            j: DMatrix::zeros(40, 3),
            next: None,
            accepted: Vec::new(),
            stop_after: usize::MAX,
        }
    }

    fn residuals_at(&self, x: &[f64]) -> DVector<f64> {
        DVector::from_fn(self.s.len(), |i, _| {
            self.t[i] - (x[0] * (x[1] * self.s[i]).exp() + x[2])
        })
    }
}

impl LeastSquaresProblem for Exponential {
    fn cost(&self) -> f64 {
        self.residuals_at(&self.x).norm_squared()
    }
    fn linearise(&mut self) -> &mut DMatrix<f64> {
        self.r = self.residuals_at(&self.x);
        for (i, s) in self.s.iter().enumerate() {
            let e = (self.x[1] * s).exp();
            self.j[(i, 0)] = e;
            self.j[(i, 1)] = self.x[0] * s * e;
            self.j[(i, 2)] = 1.0;
        }
        &mut self.j
    }
    fn residuals(&self) -> &DVector<f64> {
        &self.r
    }
    fn jacobian(&self) -> &DMatrix<f64> {
        &self.j
    }
    fn bounds(&self) -> Option<Bounds<'_>> {
        self.bounded.then_some(Bounds {
            x: &self.x,
            lower: &self.lower,
            upper: &self.upper,
        })
    }
    fn trial(&mut self, delta: &mut DVector<f64>) -> Option<f64> {
        let x: Vec<f64> = self
            .x
            .iter()
            .zip(delta.iter())
            .map(|(a, d)| a + d)
            .collect();
        let c = self.residuals_at(&x).norm_squared();
        self.next = Some((x, c));
        Some(c)
    }
    fn accept(&mut self) {
        self.x = self.next.take().unwrap().0;
    }
    fn accepted(&mut self, at: &Iterate) -> Flow {
        self.accepted.push(at.cost);
        if self.accepted.len() >= self.stop_after {
            Flow::Stop
        } else {
            Flow::Continue
        }
    }
}

/// Every damping rule reaches the exact fit of noise-free data from the
/// same start, on a passed convergence test.
#[test]
fn every_damping_rule_fits_an_exact_exponential() {
    for damping in [
        Damping::Marquardt { initial: 1e-3 },
        Damping::Trainlm {
            initial: 1e-3,
            decrease: 0.1,
            increase: 10.0,
            max: 1e10,
        },
        Damping::Nielsen { initial: 1e-3 },
    ] {
        let mut p = Exponential::new([2.0, -1.3, 0.5], [1.0, -0.5, 0.0], 0.0);
        let s = Settings {
            damping,
            ..Settings::default()
        };
        let r = minimise(&mut p, &s).unwrap();
        assert!(r.converged, "{damping:?}: {r:?}");
        for (x, t) in p.x.iter().zip([2.0, -1.3, 0.5]) {
            assert!((x - t).abs() < 1e-6, "{damping:?}: {:?}", p.x);
        }
        assert!(r.cost < 1e-20 * r.initial_cost, "{damping:?}: {r:?}");
        // Every accepted step lowered the cost.
        assert!(p.accepted.windows(2).all(|w| w[1] < w[0]));
    }
}

/// With a lower bound the unconstrained minimum violates, the run ends on
/// the bound with that column held, at the minimiser of the other two
/// columns with it fixed: the linear least-squares fit of `t − x₀·exp(b·s)`
/// by `x₀·exp(b·s) + x₂` at `b` on its bound is checked by the closed form
/// of the 2-column normal equations.
#[test]
fn a_bound_holds_its_column_at_the_constrained_minimum() {
    let truth = [2.0, -1.3, 0.5];
    let mut p = Exponential::new(truth, [1.0, -0.5, 0.0], 1e-3);
    p.bounded = true;
    p.lower[1] = -1.0;
    let r = minimise(&mut p, &Settings::default()).unwrap();
    assert!(r.converged, "{r:?}");
    assert_eq!(p.x[1], -1.0);
    assert_eq!(r.active, vec![false, true, false]);
    // Closed form of the fit of (x₀, x₂) with x₁ = −1.
    let e: Vec<f64> = p.s.iter().map(|s| (-s).exp()).collect();
    let n = e.len() as f64;
    let (se, see) = (e.iter().sum::<f64>(), e.iter().map(|v| v * v).sum::<f64>());
    let st: f64 = p.t.iter().sum();
    let set: f64 = e.iter().zip(&p.t).map(|(a, b)| a * b).sum();
    let det = see * n - se * se;
    let x0 = (set * n - se * st) / det;
    let x2 = (see * st - se * set) / det;
    assert!((p.x[0] - x0).abs() < 1e-7, "{} vs {x0}", p.x[0]);
    assert!((p.x[2] - x2).abs() < 1e-7, "{} vs {x2}", p.x[2]);
}

/// The accepted hook ends the run at the point it last saw; the start
/// callback cancels it; the budgets stop it with `MaxIterations`.
#[test]
fn callbacks_and_budgets_end_the_run() {
    let mut p = Exponential::new([2.0, -1.3, 0.5], [1.0, -0.5, 0.0], 0.0);
    p.stop_after = 2;
    let r = minimise(&mut p, &Settings::default()).unwrap();
    assert_eq!(r.reason, StopReason::Stopped);
    assert!(!r.converged);
    assert_eq!(r.linearisations, 2);
    assert_eq!(r.cost, p.accepted[1]);
    assert_eq!(r.cost, p.cost());

    struct Cancelling(Exponential);
    impl LeastSquaresProblem for Cancelling {
        fn cost(&self) -> f64 {
            self.0.cost()
        }
        fn linearise(&mut self) -> &mut DMatrix<f64> {
            self.0.linearise()
        }
        fn residuals(&self) -> &DVector<f64> {
            self.0.residuals()
        }
        fn jacobian(&self) -> &DMatrix<f64> {
            self.0.jacobian()
        }
        fn trial(&mut self, delta: &mut DVector<f64>) -> Option<f64> {
            self.0.trial(delta)
        }
        fn accept(&mut self) {
            self.0.accept()
        }
        fn start(&mut self, at: &Iterate) -> Flow {
            if at.linearisations == 3 {
                Flow::Cancel
            } else {
                Flow::Continue
            }
        }
    }
    let mut c = Cancelling(Exponential::new([2.0, -1.3, 0.5], [1.0, -0.5, 0.0], 0.0));
    assert_eq!(minimise(&mut c, &Settings::default()), Err(Cancelled));

    let mut p = Exponential::new([2.0, -1.3, 0.5], [1.0, -0.5, 0.0], 0.0);
    let s = Settings {
        max_linearisations: 2,
        ..Settings::default()
    };
    let r = minimise(&mut p, &s).unwrap();
    assert_eq!((r.reason, r.linearisations), (StopReason::MaxIterations, 2));
    let mut p = Exponential::new([2.0, -1.3, 0.5], [1.0, -0.5, 0.0], 0.0);
    let s = Settings {
        max_iterations: 1,
        ..Settings::default()
    };
    let r = minimise(&mut p, &s).unwrap();
    assert_eq!((r.reason, r.iterations), (StopReason::MaxIterations, 1));
}
