//! Fixtures shared by more than one test binary (each includes this file as its module
//! `common`; `tests/Cargo.toml` lists the binaries, so this is not one).
use ampm_core::particle::{Definiteness, Dilation, Heat, Material, PhaseParams};
use ampm_core::Real;

/// A material with heat on: a solid (`μ = 10`) and a liquid (`μ = 0`) of different heat
/// capacities and conductivities, melting at 273 K with latent heat 100 J/kg; phase change
/// as `phase_change` says.
pub fn heat_material<T: Real>(phase_change: bool) -> Material<T> {
    let f = T::from_f64;
    Material {
        solid: PhaseParams {
            mu: f(10.0),
            inv_lambda: f(0.05),
            heat_capacity: f(2.0),
            conductivity: f(1.0),
        },
        liquid: PhaseParams {
            mu: T::ZERO,
            inv_lambda: f(0.05),
            heat_capacity: f(4.0),
            conductivity: f(0.5),
        },
        plasticity: None,
        heat: Some(Heat {
            flip: f(0.9),
            melting_point: f(273.0),
            latent_heat: f(100.0),
            phase_change,
        }),
        dilation: Dilation::Explicit,
        hessian: Definiteness::Exact,
    }
}
