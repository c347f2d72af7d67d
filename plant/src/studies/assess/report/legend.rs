//! The report's legend: what its words, abbreviations and colours mean.

use super::super::Report;
use super::{zone_db, EQUAL_DB};
use std::fmt::Write as _;

/// What the report's words, abbreviations and colours mean: the page reads without the guide.
pub(super) fn legend(r: &Report) -> String {
    let min_p = r.ladder_settings.min_p;
    let duty_g = r.ladder_settings.duty_g;
    let [ab, bc, cd] = zone_db().map(|(db, _)| db);
    let mut h = String::from("<h2>How to read this report</h2>\n<dl class=\"note\">\n");
    let mut item = |term: &str, text: String| {
        let _ = writeln!(h, "<dt>{term}</dt><dd>{text}</dd>");
    };
    item(
        "Stability margin (ISO 14839-3), zones A–D",
        format!(
            "The plant adds a sine E to the sensor signal the controller reads, one axis at a time; \
             S = (what the controller read) / E is the sensitivity function, T = S − 1. The peak of |S| \
             over frequency grades the axis: zone <b>A</b> |S| &lt; 3 ({ab:.1} dB), <b>B</b> 3 to 4 ({bc:.1} dB), \
             <b>C</b> 4 to 5 ({cd:.1} dB), <b>D</b> 5 or more. <b>unstable</b>: the free decay after an offset grows, \
             so there is no margin to grade. Each axis (x, y; on a two-plane rotor x_A, y_A, x_B, y_B) is \
             measured at standstill and at the rotor's speed (“x at 500 Hz”: axis x, rotor at 500 Hz).",
        ),
    );
    item(
        "The worst axis in the verdict",
        format!(
            "The worst zone over every axis and speed, then within it the highest peak of |S|; of exactly \
             equal peaks the first measured (x before y, standstill before speed). Axes whose peak lies \
             within {EQUAL_DB} dB of it in the same zone are named after it as its equals (a machine that is \
             the same in x and y, or whose margin does not change with speed, has several)."
        ),
    );
    item(
        "Closed form",
        "|S| computed from the law's equations and the linearised bearing, where the law has them \
         (pd, pd_delay, relev's nominal design, the continuous PD); a controller process is a black box \
         and has none. On a two-plane rotor: plane A's load share as a planar rotor, not the coupled loop."
            .into(),
    );
    item(
        "Gain and phase margins",
        "The loop opened at the axis where the sensitivity is measured, every other axis closed: \
         L = 1/S − 1. PM: the smallest phase margin, at a gain crossover (|L| = 1). GM: the gain margin \
         nearest 0 dB, at a phase crossover (L real and negative); an AMB's open loop is unstable, so its \
         first crossover is at DC with a negative margin (the gain may fall by that much before the rotor \
         drops); a sampled loop adds one above the gain crossover where the gain may rise. <b>computed</b>: \
         the law's linear form on the scene's linear model (<code>plant linear</code>); <b>measured</b>: from \
         the measured S, between the measured frequencies only (DC is not measured)."
            .into(),
    );
    item(
        "Vibration (ISO 14839-2), zones A–D",
        "The levitated rotor at its speed, no shock: the peak of the orbit at the sensor against \
         C<sub>min</sub>, the minimum radial clearance (the touchdown bearing's air gap): zone <b>A</b> below \
         0.3 C<sub>min</sub>, <b>B</b> 0.3 to 0.4, <b>C</b> 0.4 to 0.5, <b>D</b> 0.5 or more. The coil current: \
         its largest swing about the mean and the RMS of the swing, per axis, against the amplifier's limit."
            .into(),
    );
    item(
        "Highest safe shock",
        format!(
            "The ladder runs the scene's shock scaled to each rung's peak (G) over many draws of the rotor's \
             angle; P(recovered) is the share of draws that end back on the orbit, with its Wilson 95 % \
             interval [lower, upper]. The highest safe shock is the highest rung up to which every rung's \
             lower bound is at least {min_p}. Colours: <b class=\"ok\">green</b> at or above the {duty_g} G \
             rung whose duty the verdict gives, <b class=\"low\">amber</b> below it, <b class=\"bad\">red</b> \
             none (not even the first rung)."
        ),
    );
    item(
        "Motion modes (the ladder's counts)",
        "How each draw ends, read over the run's last part: <b>recovered</b> back on its small unbalance \
         orbit, no contact; <b>dry whirl</b> continuous contact, whirling around the clearance circle; \
         <b>rebound</b> repeated impacts; <b>diverged</b> the run failed numerically (also at the \
         reference setting)."
            .into(),
    );
    item(
        "Duty",
        "Per shock, median [90th percentile, p90] over the rung's counted draws: time in contact, peak \
         rotor–race force and its Hertz pressure, the most loaded ball's load and pressure, the friction \
         energy, the race's peak speed and acceleration, and the ball-load cycles whose range reaches the \
         given share of Q₀, one ball's static capacity (the basis is at the end of the page)."
            .into(),
    );
    h.push_str("</dl>\n");
    h
}
