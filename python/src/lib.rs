//! The native module behind the `primo` Python package (`primo._primo`):
//! primo's DMPs, generalization, learners, the simulated pouring cell,
//! robot models (URDF chains, kinematics) and
//! one seeded run of each of the paper's experiments,
//! with NumPy arrays in and out. The typed Python layer and its docs are
//! in `python/primo/`; this crate only converts and checks.
//!
//! Every input is checked before it reaches the libraries and every error
//! they report becomes a Python exception (`errors`): no input makes a
//! Rust panic reach the interpreter.

use pyo3::prelude::*;

mod arrays;
mod cell;
mod dmp;
mod dmprun;
mod errors;
mod experiments;
mod generalize;
mod learners;
mod promp;
mod robot;
mod shaping;

#[pymodule]
fn _primo(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<dmp::Dmp>()?;
    m.add_class::<dmprun::DmpRun>()?;
    m.add_class::<promp::ProMp>()?;
    m.add_class::<generalize::Generalizer>()?;
    m.add_class::<learners::GoldenSection>()?;
    m.add_class::<learners::Illinois>()?;
    m.add_class::<learners::Secant>()?;
    m.add_class::<learners::Power>()?;
    m.add_class::<cell::Cell>()?;
    m.add_class::<robot::Robot>()?;
    m.add_function(wrap_pyfunction!(experiments::golden_run, m)?)?;
    m.add_function(wrap_pyfunction!(experiments::power_run, m)?)?;
    m.add_function(wrap_pyfunction!(experiments::check_out, m)?)?;
    m.add_function(wrap_pyfunction!(experiments::write_golden, m)?)?;
    m.add_function(wrap_pyfunction!(experiments::write_power, m)?)?;
    Ok(())
}
