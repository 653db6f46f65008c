//! Stability estimators on phase data. (OWNER: lead)
