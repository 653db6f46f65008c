//! Reports and plots.
//!
//! OWNER: helper "plot".
