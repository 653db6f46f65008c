//! Checks of output paths made before any work: an output that is one of the inputs is
//! refused (through links and `./`), so a run never replaces the data it reads.

use anyhow::Result;
use std::path::Path;

/// Refuses any of `outputs` that is the same file as one of `inputs` (`None`s skipped).
pub fn refuse_outputs_over_inputs(
    outputs: &[Option<&Path>],
    inputs: &[Option<&Path>],
) -> Result<()> {
    let inputs: Vec<&Path> = inputs.iter().flatten().copied().collect();
    for out in outputs.iter().flatten() {
        driftless::io::output::refuse_same_file(out, &inputs)?;
    }
    Ok(())
}
