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
            // Equal is EN 1992-1-1's own C90/105 (ε_c1 = ε_cu1 = 2.8 ‰): the curve
            // ends at its peak, where the strength then stays.
            if eps_cu1.is_nan() || eps_cu1 < eps_c1 {
                return Err(Error::config(
                    format!("{field}.eps_cu1"),
                    format!("must be at least eps_c1 = {eps_c1}, got {eps_cu1:?}"),
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
/// softening branch turns back on itself (snap-back) and the return has no solution;
/// the exponential crack band of Mazars needs the same (its `G_f/h` must exceed the
/// elastic energy `f_t²/(2E)` at the peak).
pub(super) fn check_crack_band(mesh: &Mesh, materials: &[Material]) -> Result<()> {
    use crate::material::{Hardening, Law};
    use crate::material::{MazarsParams, Regularisation};
    for (bi, b) in mesh.blocks.iter().enumerate() {
        let mat = &materials[b.material];
        let (strength, fracture_energy, key) = match &mat.law {
            Law::RankineHill(p) => match p.tension {
                Hardening::LinearSoftening {
                    strength,
                    fracture_energy,
                } if mat.identified_from.is_some() => {
                    (strength, fracture_energy, "identify.fracture_energy")
                }
                Hardening::LinearSoftening {
                    strength,
                    fracture_energy,
                } => (strength, fracture_energy, "tension.fracture_energy"),
                _ => continue,
            },
            Law::Mazars(MazarsParams {
                regularisation: Regularisation::CrackBand { fracture_energy },
                eps_t0,
                ..
            }) => (mat.e * eps_t0, *fracture_energy, "fracture_energy"),
            _ => continue,
        };
        let limit = 2.0 * fracture_energy * mat.e / (strength * strength);
        for e in 0..b.elements.len() {
            let h = mesh.crack_band_length(bi, e);
            if h >= limit {
                return Err(Error::config(
                    format!("materials.{}.{key}", mat.name),
                    format!("element {e} of block {bi} is {h:.3} m across (the {} of its {}), beyond the crack-band limit 2 G_f E / f_t² = {limit:.3} m{}: refine the mesh or raise G_f", if b.elements.kind.dim() == 3 { "cube root" } else { "square root" }, if b.elements.kind.dim() == 3 { "volume" } else { "area" }, if mat.identified_from.is_some() { format!(" (identified G_f = {} N/m)", crate::material::sig(fracture_energy)) } else { String::new() }),
                ));
            }
        }
    }
    Ok(())
}

/// An error naming two keys of one material that must not be given together.
fn both(field: &str, a: &str, b: &str, why: &str) -> Error {
    Error::config(
        format!("{field}.{a}"),
        format!("`{field}.{a}` and `{field}.{b}` are both given: {why}"),
    )
}

/// The concrete's data of an `identify` table and a line saying where they came
/// from. `E` is the material's own when given, else the class's `E_cm`.
fn concrete_data(
    field: &str,
    id: &crate::config::IdentifySpec,
    e: Option<f64>,
    nu: f64,
) -> Result<(crate::material::identify::ConcreteData, String)> {
    use crate::material::identify::{ConcreteData, Ec2Class};
    let f = |k: &str| format!("{field}.identify.{k}");
    let (d, source) = match &id.class {
        Some(name) => {
            for (k, v) in [("f_ct", id.f_ct), ("f_cm", id.f_cm), ("eps_c1", id.eps_c1)] {
                if v.is_some() {
                    return Err(Error::config(
                        f(k),
                        format!("give `class` or `f_ct`, `f_cm`, `eps_c1`, not both (`{k}` beside class = {name:?})"),
                    ));
                }
            }
            let c = Ec2Class::named(name).ok_or_else(|| {
                Error::config(
                    f("class"),
                    format!(
                        "unknown strength class {name:?}; EN 1992-1-1 Table 3.1 has {}",
                        Ec2Class::names()
                    ),
                )
            })?;
            let (e, which) = match e {
                Some(e) => (e, "E as given"),
                None => (c.e_cm, "E = E_cm"),
            };
            (
                ConcreteData {
                    e,
                    nu,
                    f_ct: c.f_ctm,
                    f_cm: c.f_cm,
                    eps_c1: c.eps_c1,
                },
                format!(
                    "{} (EN 1992-1-1 Table 3.1, f_ck = {:.0} MPa, {which})",
                    c.name,
                    c.f_ck / 1e6
                ),
            )
        }
        None => {
            let req = |k: &str, v: Option<f64>| -> Result<f64> {
                let v = v.ok_or_else(|| {
                    Error::config(f(k), "missing (give f_ct, f_cm and eps_c1, or class)")
                })?;
                positive(&f(k), v)?;
                Ok(v)
            };
            let e = e.ok_or_else(|| {
                Error::config(
                    format!("{field}.E"),
                    "missing (identify from f_ct, f_cm, eps_c1 needs E; only a class gives E_cm)",
                )
            })?;
            (
                ConcreteData {
                    e,
                    nu,
                    f_ct: req("f_ct", id.f_ct)?,
                    f_cm: req("f_cm", id.f_cm)?,
                    eps_c1: req("eps_c1", id.eps_c1)?,
                },
                "the concrete's data".to_string(),
            )
        }
    };
    check_elastic(field, d.e, d.nu, 1.0)?;
    if d.f_ct >= d.f_cm {
        return Err(Error::config(
            f("f_ct"),
            format!(
                "the tensile strength f_ct = {:e} Pa must lie below the compressive \
                 strength f_cm = {:e} Pa (a concrete's is about a tenth of it)",
                d.f_ct, d.f_cm
            ),
        ));
    }
    let g = crate::material::sig;
    let line = format!(
        "{source}: E = {}, nu = {}, f_ct = {}, f_cm = {}, eps_c1 = {}",
        g(d.e),
        d.nu,
        g(d.f_ct),
        g(d.f_cm),
        g(d.eps_c1)
    );
    Ok((d, line))
}

/// A strength law written back as its spec (identified laws are validated like
/// written ones).
fn hardening_spec(h: &crate::material::Hardening) -> crate::config::HardeningSpec {
    use crate::config::HardeningSpec as S;
    use crate::material::Hardening as H;
    match *h {
        H::Bilinear {
            strength,
            post_yield_modulus,
        } => S::Bilinear {
            strength,
            post_yield_modulus,
        },
        H::Ec2 {
            f_cm,
            eps_c1,
            eps_cu1,
        } => S::Ec2 {
            f_cm,
            eps_c1,
            eps_cu1,
        },
        H::LinearSoftening {
            strength,
            fracture_energy,
        } => S::LinearSoftening {
            strength,
            fracture_energy,
        },
    }
}

/// Validates one material spec into a [`Material`]; `field` prefixes error paths.
pub fn material(name: &str, field: &str, spec: &MaterialSpec) -> Result<Material> {
    use crate::material::{Law, Sls, Viscosity};
    let with = |e, nu, rho, law| -> Result<Material> {
        check_elastic(field, e, nu, rho)?;
        Ok(Material {
            name: name.into(),
            e,
            nu,
            rho,
            law,
            identified_from: None,
        })
    };
    let viscosity = |key: &str, v: f64| positive(&format!("{field}.{key}"), v);
    match *spec {
        MaterialSpec::Elastic { e, nu, rho } => with(e, nu, rho, Law::Elastic),
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
            with(e, nu, rho, Law::KelvinVoigt(v))
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
                Law::Sls(Sls {
                    alpha,
                    beta,
                    parallel: true,
                }),
            )
        }
        MaterialSpec::Maxwell { e, nu, rho, beta } => {
            viscosity("beta", beta)?;
            with(
                e,
                nu,
                rho,
                Law::Sls(Sls {
                    alpha: 1.0,
                    beta,
                    parallel: false,
                }),
            )
        }
        MaterialSpec::Mazars {
            e,
            nu,
            rho,
            variant,
            ref identify,
            eps_t0,
            eps_c0,
            a_t,
            b_t,
            a_c,
            b_c,
            beta,
            d_max,
            fracture_energy,
            nonlocal,
        } => {
            use crate::material::{MazarsParams, Regularisation};
            let regularisation = match (fracture_energy, nonlocal) {
                (Some(_), Some(_)) => {
                    return Err(both(field, "fracture_energy", "nonlocal", "one regularisation at a time: the crack band (fracture_energy) or nonlocal averaging"))
                }
                (Some(g), None) => {
                    positive(&format!("{field}.fracture_energy"), g)?;
                    for (k, v) in [("A_t", a_t), ("B_t", b_t)] {
                        if v.is_some() {
                            return Err(both(field, k, "fracture_energy", "the crack band sets the tension law (A_t = 1, B_t from G_f and the element size)"));
                        }
                    }
                    Regularisation::CrackBand { fracture_energy: g }
                }
                (None, Some(nl)) => {
                    positive(&format!("{field}.nonlocal.radius"), nl.radius)?;
                    Regularisation::Nonlocal { radius: nl.radius }
                }
                (None, None) => Regularisation::Local,
            };
            let (e, ident, from) = match identify {
                Some(id) => {
                    let raw = [
                        ("eps_t0", eps_t0),
                        ("eps_c0", eps_c0),
                        ("A_t", a_t),
                        ("B_t", b_t),
                        ("A_c", a_c),
                        ("B_c", b_c),
                    ];
                    if let Some((k, _)) = raw.iter().find(|(_, v)| v.is_some()) {
                        return Err(both(
                            field,
                            k,
                            "identify",
                            "give the raw parameters or the concrete's data, not both",
                        ));
                    }
                    if id.eps_cu1.is_some() {
                        return Err(Error::config(format!("{field}.identify.eps_cu1"), "Mazars does not use eps_cu1 (its compression law peaks at eps_c1 and softens by its own exponential)"));
                    }
                    if id.fracture_energy.is_some() {
                        return Err(Error::config(format!("{field}.identify.fracture_energy"), "put fracture_energy on the material itself: it selects the crack-band variant"));
                    }
                    let (d, from) = concrete_data(field, id, e, nu)?;
                    let m = crate::material::identify::mazars(variant, &d)
                        .map_err(|m| Error::config(format!("{field}.identify"), m))?;
                    (d.e, m, Some(from))
                }
                None => {
                    let e = e.ok_or_else(|| {
                        Error::config(
                            format!("{field}.E"),
                            "missing (give E, or identify = { class = ... } for EC2's E_cm)",
                        )
                    })?;
                    let req = |k: &str, v: Option<f64>| {
                        v.ok_or_else(|| Error::config(format!("{field}.{k}"), "missing (give the raw parameters eps_t0, A_t, B_t, A_c, B_c, or identify = { f_ct, f_cm, eps_c1 } or { class })"))
                    };
                    let crack = matches!(regularisation, Regularisation::CrackBand { .. });
                    let eps_t0 = req("eps_t0", eps_t0)?;
                    let m = crate::material::identify::MazarsIdentified {
                        eps_t0,
                        eps_c0: eps_c0.unwrap_or(eps_t0),
                        a_t: if crack { 1.0 } else { req("A_t", a_t)? },
                        b_t: if crack { 0.0 } else { req("B_t", b_t)? },
                        a_c: req("A_c", a_c)?,
                        b_c: req("B_c", b_c)?,
                    };
                    (e, m, None)
                }
            };
            // Identified values are checked like given ones; their errors name
            // `identify`.
            let name = |k: &str| {
                if from.is_some() {
                    format!("{field}.identify (identified {k})")
                } else {
                    format!("{field}.{k}")
                }
            };
            positive(&name("eps_t0"), ident.eps_t0)?;
            positive(&name("eps_c0"), ident.eps_c0)?;
            // Given parameters lie in [0, 2]; an identified A_c is whatever puts the
            // peak f_cm at ε_c1 (above 2 from C70/85 on), which (I2) guarantees
            // while E ε_c1 > f_cm (`identify::mazars` checks it).
            for (k, v) in [("A_t", ident.a_t), ("A_c", ident.a_c)] {
                let top = if from.is_some() && k == "A_c" {
                    f64::INFINITY
                } else {
                    2.0
                };
                if !(0.0..=top).contains(&v) {
                    return Err(Error::config(
                        name(k),
                        format!("must lie in [0, 2], got {v:?}"),
                    ));
                }
            }
            let crack = matches!(regularisation, Regularisation::CrackBand { .. });
            if !crack {
                positive(&name("B_t"), ident.b_t)?;
            }
            positive(&name("B_c"), ident.b_c)?;
            positive(&format!("{field}.beta"), beta)?;
            if !(d_max > 0.0 && d_max < 1.0) {
                return Err(Error::config(
                    format!("{field}.d_max"),
                    format!("must lie in (0, 1), got {d_max:?}"),
                ));
            }
            let mut m = with(
                e,
                nu,
                rho,
                Law::Mazars(MazarsParams {
                    variant,
                    eps_t0: ident.eps_t0,
                    eps_c0: ident.eps_c0,
                    a_t: if crack { 1.0 } else { ident.a_t },
                    b_t: if crack { 0.0 } else { ident.b_t },
                    a_c: ident.a_c,
                    b_c: ident.b_c,
                    beta,
                    d_max,
                    regularisation,
                }),
            )?;
            m.identified_from = from;
            Ok(m)
        }
        MaterialSpec::RankineHill {
            e,
            nu,
            rho,
            ref tension,
            ref compression,
            ref identify,
        } => {
            let (e, tension, compression, from) = match identify {
                Some(id) => {
                    for (k, v) in [
                        ("tension", tension.is_some()),
                        ("compression", compression.is_some()),
                    ] {
                        if v {
                            return Err(both(
                                field,
                                k,
                                "identify",
                                "give the strength laws or the concrete's data, not both",
                            ));
                        }
                    }
                    let (d, from) = concrete_data(field, id, e, nu)?;
                    let eps_cu1 = match (id.eps_cu1, &id.class) {
                        (Some(x), _) => x,
                        (None, Some(c)) => crate::material::identify::Ec2Class::named(c)
                            .map_or(3.5e-3, |c| c.eps_cu1),
                        (None, None) => crate::material::identify::ec2_eps_cu1(d.f_cm),
                    };
                    let gf = id
                        .fracture_energy
                        .unwrap_or_else(|| crate::material::identify::fib_fracture_energy(d.f_cm));
                    positive(&format!("{field}.identify.fracture_energy"), gf)?;
                    let (t, c) = crate::material::identify::rankine_hill(&d, eps_cu1, gf);
                    // The laws are validated as if written out.
                    let t = hardening(
                        &format!("{field}.identify (tension)"),
                        &hardening_spec(&t),
                        d.e,
                    )?;
                    let c = hardening(
                        &format!("{field}.identify (compression)"),
                        &hardening_spec(&c),
                        d.e,
                    )?;
                    let from = format!(
                        "{from}; eps_cu1 = {}, G_f = {} N/m{}",
                        crate::material::sig(eps_cu1),
                        crate::material::sig(gf),
                        if id.fracture_energy.is_none() {
                            " (fib MC2010)"
                        } else {
                            ""
                        }
                    );
                    (d.e, t, c, Some(from))
                }
                None => {
                    let e = e.ok_or_else(|| {
                        Error::config(
                            format!("{field}.E"),
                            "missing (give E, or identify = { class = ... } for EC2's E_cm)",
                        )
                    })?;
                    let t = tension.as_ref().ok_or_else(|| {
                        Error::config(
                            format!("{field}.tension"),
                            "missing (give tension and compression laws, or identify)",
                        )
                    })?;
                    let c = compression.as_ref().ok_or_else(|| {
                        Error::config(
                            format!("{field}.compression"),
                            "missing (give tension and compression laws, or identify)",
                        )
                    })?;
                    (
                        e,
                        hardening(&format!("{field}.tension"), t, e)?,
                        hardening(&format!("{field}.compression"), c, e)?,
                        None,
                    )
                }
            };
            let mut m = with(
                e,
                nu,
                rho,
                Law::RankineHill(crate::material::RankineHillParams::new(
                    tension,
                    compression,
                    e,
                )),
            )?;
            m.identified_from = from;
            Ok(m)
        }
        MaterialSpec::Kelvin { e, nu, rho, beta } => {
            viscosity("beta", beta)?;
            with(e, nu, rho, Law::KelvinVoigt(Viscosity::Proportional(beta)))
        }
    }
}
