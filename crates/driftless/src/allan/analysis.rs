//! Per-channel analysis: estimator + tau grid + confidence intervals. (OWNER: lead)
