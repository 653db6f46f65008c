//! Simulation with known truth.
//!
//! OWNER: helper "fit" (rng + static noise generator for issue 2).
