//! Material specs into materials: elastic constants, viscosities, damage and
//! strength laws, and the crack-band limit of softening laws.

use super::checks::{check_elastic, positive};
use crate::config::MaterialSpec;
use crate::error::{Error, Result};
use crate::material::Material;
use crate::mesh::Mesh;

fn hardening(
    field: &str,
    spec: &crate::config::HardeningSpec,
    e: f64,
) -> Result<crate::material::Hardening> {
    use crate::config::HardeningSpec as S;
    use crate::material::Hardening as H;
    Ok(match *spec {
        S::Bilinear {
            strength,
            post_yield_modulus,
        } => {
            positive(&format!("{field}.strength"), strength)?;
            if !post_yield_modulus.is_finite() || post_yield_modulus.abs() >= e {
                return Err(Error::config(
                    format!("{field}.post_yield_modulus"),
                    format!("must lie in (-E, E), got {post_yield_modulus:?}"),
                ));
            }
            H::Bilinear {
                strength,
                post_yield_modulus,
            }
        }
        S::Ec2 {
            f_cm,
            eps_c1,
            eps_cu1,
        } => {
            positive(&format!("{field}.f_cm"), f_cm)?;
            positive(&format!("{field}.eps_c1"), eps_c1)?;
            if eps_cu1.is_nan() || eps_cu1 <= eps_c1 {
                return Err(Error::config(
                    format!("{field}.eps_cu1"),
                    format!("must exceed eps_c1 = {eps_c1}, got {eps_cu1:?}"),
                ));
            }
            let k = 1.05 * e * eps_c1 / f_cm;
            // The curve must stay positive (η < k) and finite (η < 1/(2−k) if k < 2)
            // up to ε_cu1.
            let eta_u = eps_cu1 / eps_c1;
            let eta_max = if k < 2.0 { k.min(1.0 / (2.0 - k)) } else { k };
            if eta_u >= eta_max {
                return Err(Error::config(
                    format!("{field}.eps_cu1"),
                    format!("the EC2 curve reaches zero strength before eps_cu1 (eps_cu1/eps_c1 = {eta_u:.3} must stay below {eta_max:.3})"),
                ));
            }
            if k <= 1.05 {
                return Err(Error::config(
                    field,
                    format!(
                        "E ε_c1 / f_cm = {:.3} must exceed 1 for the curve to start elastic",
                        k / 1.05
                    ),
                ));
            }
            H::Ec2 {
                f_cm,
                eps_c1,
                eps_cu1,
            }
        }
        S::LinearSoftening {
            strength,
            fracture_energy,
        } => {
            positive(&format!("{field}.strength"), strength)?;
            positive(&format!("{field}.fracture_energy"), fracture_energy)?;
            H::LinearSoftening {
                strength,
                fracture_energy,
            }
        }
    })
}

/// Linear tension softening needs elements smaller than `2 G_f E / f_t²`, or the
/// softening branch turns back on itself (snap-back) and the return has no solution.
pub(super) fn check_crack_band(mesh: &Mesh, materials: &[Material]) -> Result<()> {
    use crate::material::{Hardening, Model};
    for (bi, b) in mesh.blocks.iter().enumerate() {
        let mat = &materials[b.material];
        let Model::RankineHill(p) = &mat.model else {
            continue;
        };
        let Hardening::LinearSoftening {
            strength,
            fracture_energy,
        } = p.tension
        else {
            continue;
        };
        let limit = 2.0 * fracture_energy * mat.e / (strength * strength);
        for e in 0..b.elements.len() {
            let x: Vec<[f64; 2]> = b
                .elements
                .element(e)
                .iter()
                .map(|&n| mesh.coords[n])
                .collect();
            let area = 0.5
                * (0..x.len())
                    .map(|a| {
                        let c = (a + 1) % x.len();
                        x[a][0] * x[c][1] - x[c][0] * x[a][1]
                    })
                    .sum::<f64>();
            let h = area.abs().sqrt();
            if h >= limit {
                return Err(Error::config(
                    format!("materials.{}.tension.fracture_energy", mat.name),
                    format!("element {e} of block {bi} is {h:.3} m across, beyond the crack-band limit 2 G_f E / f_t² = {limit:.3} m: refine the mesh or raise G_f"),
                ));
            }
        }
    }
    Ok(())
}

/// Validates one material spec into a [`Material`]; `field` prefixes error paths.
pub fn material(name: &str, field: &str, spec: &MaterialSpec) -> Result<Material> {
    use crate::material::{Model, Viscosity};
    let with = |e, nu, rho, model| -> Result<Material> {
        check_elastic(field, e, nu, rho)?;
        Ok(Material {
            name: name.into(),
            e,
            nu,
            rho,
            model,
        })
    };
    let viscosity = |key: &str, v: f64| positive(&format!("{field}.{key}"), v);
    match *spec {
        MaterialSpec::Elastic { e, nu, rho } => with(e, nu, rho, Model::Elastic),
        MaterialSpec::KelvinVoigt {
            e,
            nu,
            rho,
            alpha,
            beta,
        } => {
            let v = match (alpha, beta) {
                (Some(a), None) => {
                    viscosity("alpha", a)?;
                    Viscosity::Proportional(a)
                }
                (None, Some(b)) => {
                    viscosity("beta", b)?;
                    Viscosity::Identity(b)
                }
                _ => {
                    return Err(Error::config(
                        field,
                        "give exactly one of `alpha` (s, η = α C) or `beta` (Pa·s, η = β I)",
                    ))
                }
            };
            with(e, nu, rho, Model::KelvinVoigt(v))
        }
        MaterialSpec::Sls {
            e,
            nu,
            rho,
            alpha,
            beta,
        } => {
            viscosity("alpha", alpha)?;
            viscosity("beta", beta)?;
            with(
                e,
                nu,
                rho,
                Model::Sls {
                    alpha,
                    beta,
                    parallel: true,
                },
            )
        }
        MaterialSpec::Maxwell { e, nu, rho, beta } => {
            viscosity("beta", beta)?;
            with(
                e,
                nu,
                rho,
                Model::Sls {
                    alpha: 1.0,
                    beta,
                    parallel: false,
                },
            )
        }
        MaterialSpec::Mazars {
            e,
            nu,
            rho,
            variant,
            eps_t0,
            eps_c0,
            a_t,
            b_t,
            a_c,
            b_c,
            beta,
            d_max,
        } => {
            use crate::material::MazarsParams;
            positive(&format!("{field}.eps_t0"), eps_t0)?;
            let eps_c0 = eps_c0.unwrap_or(eps_t0);
            positive(&format!("{field}.eps_c0"), eps_c0)?;
            for (k, v) in [("A_t", a_t), ("A_c", a_c)] {
                if !(0.0..=2.0).contains(&v) {
                    return Err(Error::config(
                        format!("{field}.{k}"),
                        format!("must lie in [0, 2], got {v:?}"),
                    ));
                }
            }
            positive(&format!("{field}.B_t"), b_t)?;
            positive(&format!("{field}.B_c"), b_c)?;
            positive(&format!("{field}.beta"), beta)?;
            if !(d_max > 0.0 && d_max < 1.0) {
                return Err(Error::config(
                    format!("{field}.d_max"),
                    format!("must lie in (0, 1), got {d_max:?}"),
                ));
            }
            with(
                e,
                nu,
                rho,
                Model::Mazars(MazarsParams {
                    variant,
                    eps_t0,
                    eps_c0,
                    a_t,
                    b_t,
                    a_c,
                    b_c,
                    beta,
                    d_max,
                }),
            )
        }
        MaterialSpec::RankineHill {
            e,
            nu,
            rho,
            ref tension,
            ref compression,
        } => {
            let tension = hardening(&format!("{field}.tension"), tension, e)?;
            let compression = hardening(&format!("{field}.compression"), compression, e)?;
            with(
                e,
                nu,
                rho,
                Model::RankineHill(crate::material::RankineHillParams {
                    tension,
                    compression,
                }),
            )
        }
        MaterialSpec::Kelvin { e, nu, rho, beta } => {
            viscosity("beta", beta)?;
            with(
                e,
                nu,
                rho,
                Model::KelvinVoigt(Viscosity::Proportional(beta)),
            )
        }
    }
}
