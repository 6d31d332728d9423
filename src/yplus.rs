//! First-layer height for a target y+, from a flat-plate skin-friction correlation.
//!
//! Schlichting's turbulent flat-plate correlation `Cf = (2 log10(Re) - 0.65)^-2.3`, stated valid
//! for `Re < 1e9`. Then `tau_w = 0.5 Cf rho U^2`, `u_tau = sqrt(tau_w / rho)`,
//! `y = y+ mu / (rho u_tau)`. Without velocity, density and viscosity the same height follows
//! from the nondimensional form `y / L = y+ sqrt(2 / Cf) / Re` (with `Re = rho U L / mu`), in the
//! units of `L`.

use serde::{Deserialize, Serialize};

use crate::config::ConfigError;

/// Above this Reynolds number the correlation is not stated valid.
pub const MAX_REYNOLDS: f64 = 1e9;
/// Largest relative mismatch allowed between `reynolds` and `rho U L / mu` when both are given.
const REYNOLDS_TOLERANCE: f64 = 0.01;

/// The flow the first height is sized for (`[flow_conditions]` in the config).
#[derive(Clone, Copy, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct FlowConditions {
    /// Reynolds number on `length`.
    pub reynolds: f64,
    /// Reference length; the first height comes out in its units.
    pub length: f64,
    /// Free-stream velocity, density and dynamic viscosity (one unit system with `length`):
    /// all three or none.
    pub velocity: Option<f64>,
    pub density: Option<f64>,
    pub viscosity: Option<f64>,
}

/// The result, with the intermediate values worth printing.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FirstHeight {
    /// Skin-friction coefficient.
    pub cf: f64,
    /// Friction velocity, when the velocity is known.
    pub friction_velocity: Option<f64>,
    /// Wall shear stress, when velocity and density are known.
    pub wall_shear_stress: Option<f64>,
    /// First-layer height, in the units of `length`.
    pub height: f64,
}

fn bad(name: &str, value: impl ToString, why: &str) -> ConfigError {
    ConfigError::Parameter { name: name.into(), value: value.to_string(), why: why.into() }
}

fn positive(name: &str, value: f64) -> Result<f64, ConfigError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(bad(name, value, "must be a positive finite number"))
    }
}

/// Schlichting's flat-plate skin-friction coefficient at Reynolds number `re`.
pub fn skin_friction(re: f64) -> Result<f64, ConfigError> {
    positive("reynolds", re)?;
    // 2 log10(Re) - 0.65 > 0 needs Re > 10^0.325; well below any turbulent flow.
    if !(1e3..MAX_REYNOLDS).contains(&re) {
        return Err(bad("reynolds", re, "the Schlichting correlation is for 1e3 <= Re < 1e9"));
    }
    Ok((2.0 * re.log10() - 0.65).powf(-2.3))
}

impl FlowConditions {
    /// The first-layer height giving `yplus` at this flow.
    pub fn first_height(&self, yplus: f64) -> Result<FirstHeight, ConfigError> {
        positive("yplus", yplus)?;
        let length = positive("length", self.length)?;
        let cf = skin_friction(self.reynolds)?;
        let height = yplus * (2.0 / cf).sqrt() / self.reynolds * length;
        let result = FirstHeight { cf, friction_velocity: None, wall_shear_stress: None, height };
        match (self.velocity, self.density, self.viscosity) {
            (None, None, None) => Ok(result),
            (Some(u), Some(rho), Some(mu)) => self.dimensional(result, yplus, [u, rho, mu]),
            _ => Err(bad(
                "velocity/density/viscosity",
                format!("{:?}/{:?}/{:?}", self.velocity, self.density, self.viscosity),
                "give all three of velocity, density and viscosity, or none",
            )),
        }
    }

    fn dimensional(
        &self,
        nondimensional: FirstHeight,
        yplus: f64,
        [u, rho, mu]: [f64; 3],
    ) -> Result<FirstHeight, ConfigError> {
        let (u, rho, mu) = (positive("velocity", u)?, positive("density", rho)?, positive("viscosity", mu)?);
        let re = rho * u * self.length / mu;
        if ((re - self.reynolds) / self.reynolds).abs() > REYNOLDS_TOLERANCE {
            let why = format!(
                "differs from density * velocity * length / viscosity = {re:.6e} (inconsistent units?)"
            );
            return Err(bad("reynolds", self.reynolds, &why));
        }
        let cf = nondimensional.cf;
        let tau_w = 0.5 * cf * rho * u * u;
        let u_tau = (tau_w / rho).sqrt();
        let height = yplus * mu / (rho * u_tau);
        Ok(FirstHeight { cf, friction_velocity: Some(u_tau), wall_shear_stress: Some(tau_w), height })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ONERA M6: Re = 14.6e6 on the mean aerodynamic chord 0.64607 m.
    const M6: FlowConditions =
        FlowConditions { reynolds: 14.6e6, length: 0.64607, velocity: None, density: None, viscosity: None };

    #[test]
    fn onera_m6_matches_the_hand_calculation() {
        // log10(14.6e6) = 7.164353; 2 * 7.164353 - 0.65 = 13.678706; ^-2.3 = 2.43835e-3;
        // sqrt(2 / Cf) = 28.6396; y = 28.6396 / 14.6e6 * 0.64607 m = 1.26734e-6 m.
        let h = M6.first_height(1.0).unwrap();
        assert!((h.cf - 2.43835e-3).abs() < 1e-8, "{}", h.cf);
        assert!((h.height - 1.26734e-6).abs() < 1e-11, "{}", h.height);
        // Linear in y+, and in the length's units (mm in, mm out).
        let mm = FlowConditions { length: 646.07, ..M6 };
        assert!((mm.first_height(5.0).unwrap().height - 5.0 * 1.26734e-3).abs() < 1e-8);
    }

    #[test]
    fn dimensional_form_agrees_with_the_nondimensional_one() {
        // Sea-level air; the velocity that gives Re = 14.6e6 on the chord.
        let (rho, mu) = (1.225, 1.7894e-5);
        let u = M6.reynolds * mu / (rho * M6.length);
        let air = FlowConditions { velocity: Some(u), density: Some(rho), viscosity: Some(mu), ..M6 };
        let h = air.first_height(1.0).unwrap();
        let nondimensional = M6.first_height(1.0).unwrap();
        assert!((h.height / nondimensional.height - 1.0).abs() < 1e-12);
        let u_tau = h.friction_velocity.unwrap();
        assert!((u_tau - u * (h.cf / 2.0).sqrt()).abs() < 1e-12 * u);
        assert!((h.wall_shear_stress.unwrap() - rho * u_tau * u_tau).abs() < 1e-9);
    }

    #[test]
    fn rejects_bad_inputs_by_name() {
        let cases: [(FlowConditions, f64, &str); 7] = [
            (FlowConditions { reynolds: -1.0, ..M6 }, 1.0, "reynolds"),
            (FlowConditions { reynolds: 2e9, ..M6 }, 1.0, "Re < 1e9"),
            (FlowConditions { length: f64::NAN, ..M6 }, 1.0, "length"),
            (M6, 0.0, "yplus"),
            (M6, f64::INFINITY, "yplus"),
            (FlowConditions { velocity: Some(10.0), ..M6 }, 1.0, "all three"),
            (
                FlowConditions { velocity: Some(10.0), density: Some(1.2), viscosity: Some(1.8e-5), ..M6 },
                1.0,
                "inconsistent units",
            ),
        ];
        for (flow, yplus, expected) in cases {
            let e = flow.first_height(yplus).unwrap_err().to_string();
            assert!(e.contains(expected), "{flow:?} y+ {yplus}: {e}");
        }
    }
}
