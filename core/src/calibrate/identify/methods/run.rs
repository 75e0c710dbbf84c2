//! One method's run: [`run`] dispatches on the table's [`Run`] to the
//! model-based fits (through the [`Cache`]), the joint maps, a compensator
//! or `auto`.

use super::auto::run_auto;
use super::cache::Cache;
use super::compensated::run_compensated;
use super::context::{Context, MethodProgress, Outcome};
use super::maps::run_maps;
use super::{Method, MethodError, Run};

/// Runs `method` (its row's [`Run`]).
pub(crate) fn run(
    method: Method,
    ctx: &Context,
    cache: &mut Cache,
    progress: &MethodProgress,
) -> Result<Outcome, MethodError> {
    let mut lm = |it: usize, rms: f64| progress.lm(it, rms);
    match method.row().run {
        Run::Km => cache.km_fit(ctx, &mut lm).map(Outcome::plain),
        Run::Skcm => cache.skcm_fit(ctx, &mut lm).map(Outcome::plain),
        Run::SkcmTlbo => {
            let warm = match cache.km() {
                Some(f) => f.clone(),
                None => ctx.km(&mut lm)?,
            };
            ctx.skcm_tlbo(&warm, &mut |gen, best| progress.generation(gen, best))
                .map(Outcome::plain)
        }
        Run::SkcmPayload => cache
            .skcm_fit(ctx, &mut lm)
            .and_then(|s| ctx.skcm_payload(&s.fit, &mut lm))
            .map(Outcome::plain),
        Run::Maps(base) => run_maps(ctx, cache, base, &mut |f, it, loss| {
            progress.fraction(f, it, loss)
        }),
        Run::Compensated(c) => run_compensated(ctx, cache, method, c, &mut |s| progress.step(s)),
        Run::Auto => run_auto(ctx, cache, &mut |s| progress.step(s)),
    }
}
