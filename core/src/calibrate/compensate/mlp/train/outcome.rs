//! What a trainer of the MLP found and why it stopped.

/// What a trainer found and how it ended.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct TrainOutcome {
    /// Flat weight vector in normalised units.
    pub weights: Vec<f64>,
    /// Epochs (LM), iterations (IWO) or generations (TLBO) run.
    pub epochs: usize,
    /// Loss evaluations.
    pub evaluations: usize,
    /// Final training loss (normalised units, module docs).
    pub loss: f64,
    pub stop: TrainStop,
}

/// Why a trainer stopped, and whether the null network replaced its result.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct TrainStop {
    pub reason: TrainStopReason,
    pub null_network: Option<NullNetwork>,
}

/// Why a trainer stopped.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum TrainStopReason {
    /// LM: every one of `max_epochs` epochs ran.
    Epochs(usize),
    /// LM: the largest gradient component fell below `floor`.
    GradientVanished { floor: f64 },
    /// LM: no damping up to `mu_max` lowered the loss.
    DampingExhausted { mu_max: f64 },
    /// LM: the held-out loss was not better for `max_fail` epochs in a row.
    EarlyStop { max_fail: usize },
    /// IWO: every iteration ran.
    Iterations(usize),
    /// TLBO: every generation ran.
    Generations(usize),
}

/// Why the null network (it predicts the mean residual) replaced the trained one.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum NullNetwork {
    /// LM: no epoch beat it on the held-out part.
    NoEpochBetter,
    /// IWO, TLBO: the network does not beat it on the held-out part by
    /// `standard_errors` standard errors of the paired per-sample gains.
    NotSignificant { standard_errors: f64 },
}

impl std::fmt::Display for TrainStop {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.reason {
            TrainStopReason::Epochs(n) => write!(f, "{n} epochs")?,
            TrainStopReason::GradientVanished { floor } => write!(f, "gradient below {floor:e}")?,
            TrainStopReason::DampingExhausted { mu_max } => write!(f, "mu above {mu_max:e}")?,
            TrainStopReason::EarlyStop { max_fail } => write!(
                f,
                "early stop: held-out loss not better for {max_fail} epochs"
            )?,
            TrainStopReason::Iterations(n) => write!(f, "{n} iterations")?,
            TrainStopReason::Generations(n) => write!(f, "{n} generations")?,
        }
        match &self.null_network {
            None => Ok(()),
            Some(NullNetwork::NoEpochBetter) => write!(
                f,
                "; no epoch beat the mean residual on the held-out part: null network"
            ),
            Some(NullNetwork::NotSignificant { standard_errors }) => write!(
                f,
                "; not better than the mean residual on the held-out part by {standard_errors} standard errors: null network"
            ),
        }
    }
}
