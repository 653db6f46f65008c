//! The verdict a calibration gives on its own quality figures.
//!
//! Every fit reports χ²/ν = Σ (r_i/σ_i)² / ν, the residuals r_i weighted by the noise σ_i
//! the data themselves imply (ν = equations − parameters). With honest σ and an adequate
//! model its expectation is 1 and its standard deviation √(2/ν); well above that the
//! residuals are not noise: the model misses an effect, the σ are too small, or the data
//! are not what the method assumes. A figure can also be *implausible* for a calibration
//! at all (e.g. the gravity direction carried by the calibrated gyro off by tens of
//! degrees): such a result must not be used without an explicit decision to accept it.

use serde::Serialize;

/// Quality figures of one fitted triad.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct FitQuality {
    /// χ²/ν of the noise-weighted residuals (NaN without redundancy).
    pub chi2_per_dof: f64,
    /// Degrees of freedom ν.
    pub dof: usize,
    /// Each warning names the figure, its value, the threshold and the likely causes.
    pub warnings: Vec<String>,
    /// Why the result is not a usable calibration; empty when it is plausible.
    pub implausible: Vec<String>,
}

impl FitQuality {
    /// The figures, with a warning when χ²/ν exceeds `warn_chi2_per_dof`; `causes` lists
    /// the likely causes for this fit.
    pub(crate) fn from_chi2(
        chi2: f64,
        dof: usize,
        warn_chi2_per_dof: f64,
        causes: &str,
    ) -> FitQuality {
        let chi2_per_dof = if dof > 0 { chi2 / dof as f64 } else { f64::NAN };
        let mut warnings = Vec::new();
        if chi2_per_dof > warn_chi2_per_dof {
            warnings.push(format!(
                "χ²/dof {chi2_per_dof:.3} (ν = {dof}) is above {warn_chi2_per_dof}: the residuals are {:.1}× the noise; likely causes: {causes}",
                chi2_per_dof.sqrt()
            ));
        } else if chi2.is_nan() {
            warnings.push("χ²/dof is not a number: a residual or its noise σ is not finite".into());
        }
        FitQuality {
            chi2_per_dof,
            dof,
            warnings,
            implausible: Vec::new(),
        }
    }

    /// True when the result is plausible (no entry in [`FitQuality::implausible`]).
    pub fn is_plausible(&self) -> bool {
        self.implausible.is_empty()
    }
}

/// Default χ²/ν above which a calibration warns: the residuals are √10 ≈ 3.2× the noise.
/// Not the 1 + 3√(2/ν) a χ² test would use: the noise σ of the calibrations are lower
/// bounds (white noise and bias wander at the averaging length; slower drift over the
/// recording is not in them), and a consumer-grade sensor simulated with exactly the
/// calibration's model reaches χ²/ν ≈ 7.
pub const DEFAULT_WARN_CHI2_PER_DOF: f64 = 10.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warning_only_above_threshold() {
        let ok = FitQuality::from_chi2(20.0, 10, 3.0, "x");
        assert_eq!(ok.chi2_per_dof, 2.0);
        assert!(ok.warnings.is_empty() && ok.is_plausible());
        let bad = FitQuality::from_chi2(400.0, 10, 3.0, "unmodelled drift");
        assert_eq!(bad.warnings.len(), 1);
        assert!(
            bad.warnings[0].contains("unmodelled drift"),
            "{:?}",
            bad.warnings
        );
        assert!(
            FitQuality::from_chi2(1.0, 0, 3.0, "x")
                .chi2_per_dof
                .is_nan()
        );
    }
}
