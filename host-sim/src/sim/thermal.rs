//! Two-node lumped thermal model of the gyro after power-on: fibre coil and housing,
//! coupled to each other and the housing to the ambient, heated by the dissipation.
//!
//! C_c dT_c/dt = P_c + G_ch (T_h - T_c)
//! C_h dT_h/dt = P_h - G_ch (T_h - T_c) - G_ha (T_h - T_a)
//!
//! The system is linear with constant input, so each step uses the exact discrete
//! transition (matrix exponential by a converged Taylor series): no integration error
//! at any sample rate.

use super::params::ThermalParams;

type Mat2 = [[f64; 2]; 2];

fn mul(a: &Mat2, b: &Mat2) -> Mat2 {
    let mut c = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            c[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j];
        }
    }
    c
}

fn apply(a: &Mat2, x: [f64; 2]) -> [f64; 2] {
    [
        a[0][0] * x[0] + a[0][1] * x[1],
        a[1][0] * x[0] + a[1][1] * x[1],
    ]
}

/// The thermal state of one power-on and its exact stepper.
#[derive(Clone, Debug)]
pub struct ThermalNet {
    a: Mat2,
    b: [f64; 2],
    phi: Mat2,
    gamma: Mat2,
    /// [coil, housing] temperature, degC.
    x: [f64; 2],
    ambient_c: f64,
}

impl ThermalNet {
    /// Sets up the network at `ambient_c` with the dissipation scaled by `power_scale`,
    /// both nodes starting at `start_c`, stepping by `dt_s`.
    pub fn new(
        p: &ThermalParams,
        ambient_c: f64,
        power_scale: f64,
        start_c: f64,
        dt_s: f64,
    ) -> Self {
        let g_ha = p.housing_ambient_w_per_k
            * (1.0 + p.housing_ambient_tempco_per_k * (ambient_c - 20.0)).max(0.1);
        let power =
            (p.power_w + p.tec_w_per_k * (ambient_c - p.tec_setpoint_c).abs()) * power_scale;
        let (cc, ch, g) = (
            p.coil_heat_capacity_j_per_k,
            p.housing_heat_capacity_j_per_k,
            p.coil_housing_w_per_k,
        );
        let a = [[-g / cc, g / cc], [g / ch, -(g + g_ha) / ch]];
        let b = [
            power * p.coil_power_fraction / cc,
            (power * (1.0 - p.coil_power_fraction) + g_ha * ambient_c) / ch,
        ];
        // phi = sum (A dt)^n / n!, gamma = sum A^n dt^(n+1) / (n+1)!
        let mut phi = [[1.0, 0.0], [0.0, 1.0]];
        let mut gamma = [[dt_s, 0.0], [0.0, dt_s]];
        let mut term = [[1.0, 0.0], [0.0, 1.0]]; // A^n dt^n / n!
        for n in 1..40 {
            term = mul(&term, &a);
            let k = dt_s / n as f64;
            term.iter_mut().flatten().for_each(|v| *v *= k);
            let mut small = true;
            for i in 0..2 {
                for j in 0..2 {
                    phi[i][j] += term[i][j];
                    let g_term = term[i][j] * dt_s / (n + 1) as f64;
                    gamma[i][j] += g_term;
                    small &= term[i][j].abs() < 1e-18;
                }
            }
            if small {
                break;
            }
        }
        Self {
            a,
            b,
            phi,
            gamma,
            x: [start_c, start_c],
            ambient_c,
        }
    }

    /// The powered-on equilibrium [coil, housing], degC.
    pub fn steady_state_c(&self) -> [f64; 2] {
        let a = &self.a;
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        // x* = -A^-1 b
        let inv = [
            [a[1][1] / det, -a[0][1] / det],
            [-a[1][0] / det, a[0][0] / det],
        ];
        let v = apply(&inv, self.b);
        [-v[0], -v[1]]
    }

    /// Puts the network at its powered-on equilibrium (a warm gyro).
    pub fn settle(&mut self) {
        self.x = self.steady_state_c();
    }

    /// Advances by one step.
    pub fn step(&mut self) {
        let x = apply(&self.phi, self.x);
        let u = apply(&self.gamma, self.b);
        self.x = [x[0] + u[0], x[1] + u[1]];
    }

    /// Coil temperature, degC.
    pub fn coil_c(&self) -> f64 {
        self.x[0]
    }

    /// Housing temperature, degC.
    pub fn housing_c(&self) -> f64 {
        self.x[1]
    }

    /// Ambient temperature, degC.
    pub fn ambient_c(&self) -> f64 {
        self.ambient_c
    }

    /// [dT_coil/dt, dT_housing/dt], degC/s.
    pub fn rates_cps(&self) -> [f64; 2] {
        let ax = apply(&self.a, self.x);
        [ax[0] + self.b[0], ax[1] + self.b[1]]
    }

    /// [d2T_coil/dt2, d2T_housing/dt2], degC/s^2.
    pub fn accels_cps2(&self) -> [f64; 2] {
        apply(&self.a, self.rates_cps())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::GyroParams;

    #[test]
    fn exact_step_matches_fine_euler_and_settles() {
        let p = GyroParams::paper_default().thermal;
        let mut coarse = ThermalNet::new(&p, 20.0, 1.0, 20.0, 10.0);
        let mut fine = ThermalNet::new(&p, 20.0, 1.0, 20.0, 0.001);
        for _ in 0..60 {
            coarse.step();
        }
        for _ in 0..600_000 {
            let r = fine.rates_cps();
            fine.x = [fine.x[0] + r[0] * 0.001, fine.x[1] + r[1] * 0.001];
        }
        assert!(
            (coarse.coil_c() - fine.coil_c()).abs() < 2e-3,
            "{} {}",
            coarse.coil_c(),
            fine.coil_c()
        );
        let ss = coarse.steady_state_c();
        for _ in 0..10_000 {
            coarse.step();
        }
        assert!((coarse.coil_c() - ss[0]).abs() < 1e-9 && coarse.rates_cps()[0].abs() < 1e-12);
        assert!(
            ss[0] > 24.0 && ss[0] < 30.0,
            "coil warms by several degC: {}",
            ss[0]
        );
    }
}
