//! Terms in the customary datasheet units (deg/√h, deg/h, mg …) and their labels.

use driftless_model::units::{
    DEG, DEG_PER_H, DEG_PER_H_PER_SQRT_H, DEG_PER_SQRT_H, HOUR_S, M_PER_S_PER_SQRT_H, MICRO_G,
    MILLI_G,
};
use serde::{Deserialize, Serialize};

use crate::allan::fit::{NoiseFit, Term, TermKind};

use super::Quantity;

pub(super) const ALL_TERMS: [TermKind; 6] = [
    TermKind::Quantization,
    TermKind::White,
    TermKind::BiasInstability,
    TermKind::RateRandomWalk,
    TermKind::RateRamp,
    TermKind::GaussMarkov,
];

pub(crate) fn term_label(k: TermKind) -> &'static str {
    match k {
        TermKind::Quantization => "quantization Q",
        TermKind::White => "white N",
        TermKind::BiasInstability => "bias instab. B",
        TermKind::RateRandomWalk => "rate rand. walk K",
        TermKind::RateRamp => "rate ramp R",
        TermKind::GaussMarkov => "GM sigma",
    }
}

/// SI unit of each term for rate samples in `unit` (u·s, u·√s, u, u/√s, u/s).
pub(crate) fn si_term_units(unit: &str) -> impl Fn(TermKind) -> String + '_ {
    let u = if unit.is_empty() { "u" } else { unit };
    move |k| match k {
        TermKind::Quantization => format!("({u})·s"),
        TermKind::White => format!("({u})·sqrt(s)"),
        TermKind::BiasInstability | TermKind::GaussMarkov => u.to_string(),
        TermKind::RateRandomWalk => format!("({u})/sqrt(s)"),
        TermKind::RateRamp => format!("({u})/s"),
    }
}

pub(crate) fn fmt_num(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if !v.is_finite() {
        format!("{v}")
    } else if (1e-3..1e5).contains(&v.abs()) {
        // five significant digits
        let d = (4 - v.abs().log10().floor() as i32).clamp(0, 7) as usize;
        format!("{v:.d$}")
    } else {
        format!("{v:.4e}")
    }
}

/// Display units of a term for a channel quantity: (unit name, size of one display unit
/// in SI). Angular rate → gyro units, specific force → accelerometer units; other
/// quantities have none (their terms stay in SI).
pub fn display_units(quantity: Quantity, term: TermKind) -> &'static [(&'static str, f64)] {
    GyroOrAccel::of(quantity).map_or(&[], |g| g.display_units(term))
}

#[derive(Clone, Copy)]
pub(super) enum GyroOrAccel {
    Gyro,
    Accel,
}

impl GyroOrAccel {
    fn of(q: Quantity) -> Option<GyroOrAccel> {
        match q {
            Quantity::AngularRate => Some(GyroOrAccel::Gyro),
            Quantity::SpecificForce => Some(GyroOrAccel::Accel),
            Quantity::Temperature | Quantity::Other => None,
        }
    }

    /// Display units of a term: (unit name, size of one display unit in SI).
    fn display_units(self, term: TermKind) -> &'static [(&'static str, f64)] {
        const DEG_PER_H2: f64 = DEG / (HOUR_S * HOUR_S);
        const M_PER_S_PER_H15: f64 = 1.0 / (HOUR_S * 60.0);
        match (self, term) {
            (GyroOrAccel::Gyro, TermKind::Quantization) => &[("deg", DEG), ("urad", 1e-6)],
            (GyroOrAccel::Gyro, TermKind::White) => {
                &[("deg/sqrt(h)", DEG_PER_SQRT_H), ("deg/s/sqrt(Hz)", DEG)]
            }
            (GyroOrAccel::Gyro, TermKind::BiasInstability | TermKind::GaussMarkov) => {
                &[("deg/h", DEG_PER_H)]
            }
            (GyroOrAccel::Gyro, TermKind::RateRandomWalk) => {
                &[("deg/h/sqrt(h)", DEG_PER_H_PER_SQRT_H)]
            }
            (GyroOrAccel::Gyro, TermKind::RateRamp) => &[("deg/h^2", DEG_PER_H2)],
            (GyroOrAccel::Accel, TermKind::Quantization) => &[("m/s", 1.0)],
            (GyroOrAccel::Accel, TermKind::White) => &[
                ("m/s/sqrt(h)", M_PER_S_PER_SQRT_H),
                ("ug/sqrt(Hz)", MICRO_G),
            ],
            (GyroOrAccel::Accel, TermKind::BiasInstability | TermKind::GaussMarkov) => {
                &[("ug", MICRO_G), ("mg", MILLI_G)]
            }
            (GyroOrAccel::Accel, TermKind::RateRandomWalk) => {
                &[("m/s^2/sqrt(s)", 1.0), ("m/s/h^1.5", M_PER_S_PER_H15)]
            }
            (GyroOrAccel::Accel, TermKind::RateRamp) => &[("m/s^3", 1.0)],
        }
    }
}

/// One term in a display unit. A term that was fitted but not detected has
/// `detected = false`, value = lo = 0 and `hi` = its upper limit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DisplayValue {
    /// Which term.
    pub term: TermKind,
    /// Display unit.
    pub unit: String,
    /// Estimate.
    pub value: f64,
    /// Lower confidence bound.
    pub lo: f64,
    /// Upper confidence bound (upper limit when not detected).
    pub hi: f64,
    /// Whether the term was detected.
    pub detected: bool,
}

/// Continuous-time terms of a fit in display units (every unit of
/// [`display_units`]), detected terms first in model order, then upper limits.
pub fn display_terms(fit: &NoiseFit, quantity: Quantity) -> Vec<DisplayValue> {
    let mut out = Vec::new();
    for kind in [
        TermKind::Quantization,
        TermKind::White,
        TermKind::BiasInstability,
        TermKind::RateRandomWalk,
        TermKind::RateRamp,
        TermKind::GaussMarkov,
    ] {
        let (t, detected) = match fit.term(kind) {
            Some(t) => (t, true),
            None => match fit.not_detected.iter().find(|u| u.term == kind) {
                Some(u) => (
                    Term {
                        value: 0.0,
                        lo: 0.0,
                        hi: u.upper,
                    },
                    false,
                ),
                None => continue,
            },
        };
        for &(unit, size) in display_units(quantity, kind) {
            out.push(DisplayValue {
                term: kind,
                unit: unit.to_string(),
                value: t.value / size,
                lo: t.lo / size,
                hi: t.hi / size,
                detected,
            });
        }
    }
    out
}
