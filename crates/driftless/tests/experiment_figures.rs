//! The experiment's figures as the report draws them (built-in scenario, 2 Monte Carlo
//! runs, 9 outages): the per-outage chart has one group per outage — not per run — and no
//! two things in one panel look alike.

use driftless::experiment::monte_carlo::run_experiment;
use driftless::experiment::report::figures;
use driftless::experiment::{ExperimentScenario, prepare};
use driftless::report::plot::Plot;

/// `(name, panel)` of every panel of every figure of a 2-run built-in experiment, and the
/// number of outages.
fn panels() -> (Vec<(String, Plot)>, usize) {
    let sc = ExperimentScenario::builtin_adi_like().expect("scenario");
    let p = prepare(sc).expect("prepare");
    let r = run_experiment(&p, Some(2), &|_, _, _| {}).expect("run");
    assert_eq!(r.runs.len(), 2);
    let out = figures(&p, &r)
        .into_iter()
        .flat_map(|(name, _, fig)| fig.panels.into_iter().map(move |pl| (name.clone(), pl)))
        .collect();
    (out, p.outages.len())
}

/// What tells two legend entries of a panel apart: colour and stroke or marker.
fn looks(p: &Plot) -> Vec<(String, String)> {
    let mut v = Vec::new();
    for s in &p.series {
        v.push((
            s.name.clone(),
            format!("series {:?} {:?}", s.color, s.marker),
        ));
    }
    // A line labelled on the plot is told apart by its label.
    for l in p.lines.iter().filter(|l| l.label.is_none()) {
        v.push((l.name.clone(), format!("line {:?} {:?}", l.color, l.style)));
    }
    for b in &p.bars {
        v.push((b.name.clone(), format!("bars {:?}", b.color)));
    }
    // An unnamed piece belongs to a named entry drawn alike (the trajectory's outage
    // tracks after the first): only legend entries must differ.
    v.retain(|(name, _)| !name.trim().is_empty());
    v
}

#[test]
fn outage_bars_are_outages_and_no_panel_repeats_a_look() {
    let (panels, outages) = panels();
    assert_eq!(outages, 9);
    // "Error per GNSS outage": one group per outage (#1..#9), each case a bar per outage.
    let per_outage: Vec<&Plot> = panels
        .iter()
        .filter(|(_, p)| p.title == "Error per GNSS outage")
        .map(|(_, p)| p)
        .collect();
    assert_eq!(per_outage.len(), 1, "one per-outage chart");
    let chart = per_outage[0];
    assert_eq!(chart.x_label, "GNSS outage");
    let ticks: Vec<&str> = chart
        .x_tick_labels
        .as_ref()
        .expect("group labels")
        .iter()
        .map(|(_, l)| l.as_str())
        .collect();
    let want: Vec<String> = (1..=outages).map(|k| format!("#{k}")).collect();
    assert_eq!(ticks, want, "groups are the outages");
    assert_eq!(chart.bars.len(), 4, "one bar set per case");
    for b in &chart.bars {
        assert_eq!(b.y.len(), outages, "{}: one bar per outage", b.name);
    }
    // The Monte Carlo chart groups runs and says so.
    let (_, mc) = panels
        .iter()
        .find(|(n, _)| n == "monte-carlo")
        .expect("monte-carlo figure");
    assert_ne!(mc.title, "Error per GNSS outage");
    assert_eq!(mc.x_tick_labels.as_ref().map(Vec::len), Some(2));
    // No two things of one panel look alike (the error growth's outages #1 and #8 both
    // black was this).
    for (name, p) in &panels {
        let l = looks(p);
        if name == "error-growth" {
            assert!(l.len() >= outages, "{:?}: {} entries", p.title, l.len());
        }
        for (i, (na, a)) in l.iter().enumerate() {
            for (nb, b) in &l[i + 1..] {
                assert_ne!(a, b, "{name} / {:?}: {na:?} and {nb:?} look alike", p.title);
            }
        }
    }
}
