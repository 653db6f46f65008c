//! Tau grids. (OWNER: lead)
