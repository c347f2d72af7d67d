//! `pd_delay`'s registry entry: the delay-aware discrete PD of
//! [`crate::discrete_pd`], designed for the sampling period and the command
//! delay (no parameters of its own).

use crate::discrete_pd::{DelayPd, DelayPdGains};
use crate::law::{ControlLaw, Design, LawEntry, LawError};
use crate::params::Params;

/// `pd_delay`: the design's poles held exactly by a PD designed for the period and the delay.
pub const LAW: LawEntry = LawEntry {
    name: "pd_delay",
    summary: "a discrete PD placing the design's poles exactly for the rate and the command delay",
    build,
};

fn build(design: &Design, params: &Params) -> Result<Box<dyn ControlLaw>, LawError> {
    params.reader(LAW.name).finish()?;
    let gains = DelayPdGains::from_design(&design.pd(), &design.constants, design.period_s, design.delay_samples)?;
    Ok(Box::new(DelayPd::new(gains, design.period_s)))
}
