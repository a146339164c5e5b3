//! Layups through the thickness: layers of different materials, their classical-lamination-theory
//! properties (mass, heat capacity, bending stiffness about the neutral axis, thermal resistance)
//! and a small library of materials.
//!
//! Layers are listed from the Sun-facing (front) side to the back. Depth s is measured from the
//! front face (s = 0) to the back face (s = d). Each layer is isotropic in the plane and bends as a
//! beam of unit width (Poisson coupling left out, as in the panel's E I).

use crate::error::{require_non_negative, require_positive, Error, Result};
use crate::inputs::panel::{Panel, MAX_EXPANSION};

/// One layer of a laminate (all SI).
#[derive(Debug, Clone, PartialEq)]
pub struct Layer {
    /// h, m (> 0).
    pub thickness: f64,
    /// k through the thickness, W/(m K) (> 0).
    pub conductivity: f64,
    /// ρ, kg/m³ (> 0).
    pub density: f64,
    /// c, J/(kg K) (> 0).
    pub specific_heat: f64,
    /// E in the plane, Pa (>= 0: a honeycomb core carries no bending stress).
    pub youngs_modulus: f64,
    /// a in the plane, 1/K (any sign: carbon fibre laminates may shrink when heated).
    pub expansion_coeff: f64,
    /// A name for messages and tables.
    pub name: String,
}

/// The fields of a layer, in declaration order (the Python layer uses them).
/// The default stress-free reference temperature T_ref of a laminate, K (20 °C).
pub const REFERENCE_TEMPERATURE: f64 = 293.15;

pub const LAYER_FIELDS: [&str; 6] = [
    "thickness",
    "conductivity",
    "density",
    "specific_heat",
    "youngs_modulus",
    "expansion_coeff",
];

impl Layer {
    /// Checks every field; the error names the layer and the field ("layer 'core': density").
    pub fn validate(&self) -> Result<()> {
        let named = |field: &str| format!("layer '{}': {field}", self.name);
        for (field, v) in [
            ("thickness", self.thickness),
            ("conductivity", self.conductivity),
            ("density", self.density),
            ("specific_heat", self.specific_heat),
        ] {
            require_positive(&named(field), v)?;
        }
        require_non_negative(&named("youngs_modulus"), self.youngs_modulus)?;
        crate::error::require_finite(&named("expansion_coeff"), self.expansion_coeff)?;
        if self.expansion_coeff.abs() > MAX_EXPANSION {
            return Err(Error::invalid(
                &named("expansion_coeff"),
                self.expansion_coeff,
                &format!(
                    "must be within ±{MAX_EXPANSION:e} 1/K (an expansion coefficient, not a percentage)"
                ),
            ));
        }
        Ok(())
    }

    /// Thermal diffusivity k/(ρ c), m²/s.
    pub fn diffusivity(&self) -> f64 {
        self.conductivity / (self.density * self.specific_heat)
    }
}

/// A stack of layers with its surface properties and the temperature at which it is stress-free.
#[derive(Debug, Clone, PartialEq)]
pub struct Laminate {
    /// From the Sun-facing side to the back.
    pub layers: Vec<Layer>,
    /// ε of the front face, in (0, 1].
    pub emissivity_front: f64,
    /// ε of the back face, in (0, 1].
    pub emissivity_back: f64,
    /// α of the front face, in (0, 1].
    pub absorptivity: f64,
    /// T_ref, K: the stress-free temperature. A laminate whose expansion is not symmetric about
    /// its neutral axis (a bimetal) bends under a uniform temperature change from T_ref.
    pub reference_temperature: f64,
}

impl Laminate {
    pub fn validate(&self) -> Result<()> {
        if self.layers.is_empty() {
            return Err(Error::invalid(
                "layers",
                0,
                "a laminate needs at least one layer",
            ));
        }
        for layer in &self.layers {
            layer.validate()?;
        }
        for (name, v) in [
            ("emissivity_front", self.emissivity_front),
            ("emissivity_back", self.emissivity_back),
            ("absorptivity", self.absorptivity),
        ] {
            if !(v.is_finite() && v > 0.0 && v <= 1.0) {
                return Err(Error::invalid(name, v, "must be in (0, 1]"));
            }
        }
        require_positive("reference_temperature", self.reference_temperature)?;
        if self.bending_stiffness() <= 0.0 {
            return Err(Error::invalid(
                "layers",
                "every youngs_modulus = 0",
                "at least one layer must carry bending stress (youngs_modulus > 0)",
            ));
        }
        Ok(())
    }

    /// d, total thickness, m.
    pub fn thickness(&self) -> f64 {
        self.layers.iter().map(|l| l.thickness).sum()
    }

    /// Depths of the layer boundaries from the front face, m: 0, h₁, h₁+h₂, …, d.
    pub fn interfaces(&self) -> Vec<f64> {
        let mut s = vec![0.0];
        for l in &self.layers {
            s.push(s[s.len() - 1] + l.thickness);
        }
        s
    }

    /// Σ ρ h, mass per unit area, kg/m².
    pub fn mass_per_area(&self) -> f64 {
        self.layers.iter().map(|l| l.density * l.thickness).sum()
    }

    /// Σ ρ c h, heat capacity per unit area, J/(m² K).
    pub fn heat_capacity(&self) -> f64 {
        self.layers
            .iter()
            .map(|l| l.density * l.specific_heat * l.thickness)
            .sum()
    }

    /// Σ h/k, thermal resistance face to face, m² K/W.
    pub fn thermal_resistance(&self) -> f64 {
        self.layers
            .iter()
            .map(|l| l.thickness / l.conductivity)
            .sum()
    }

    /// A = Σ E h, extensional stiffness per unit width, N/m.
    pub fn extensional_stiffness(&self) -> f64 {
        self.layers
            .iter()
            .map(|l| l.youngs_modulus * l.thickness)
            .sum()
    }

    /// s_n, depth of the neutral axis from the front face, m: the modulus-weighted centroid
    /// Σ E h s̄ / Σ E h, where the bending–extension coupling B of lamination theory vanishes.
    pub fn neutral_axis(&self) -> f64 {
        let s = self.interfaces();
        let first: f64 = self
            .layers
            .iter()
            .enumerate()
            .map(|(i, l)| l.youngs_modulus * l.thickness * 0.5 * (s[i] + s[i + 1]))
            .sum();
        first / self.extensional_stiffness()
    }

    /// D = Σ E (h³/12 + h (s̄ − s_n)²), bending stiffness per unit width about the neutral
    /// axis, N m (the D of lamination theory reduced by B²/A, which is zero about s_n).
    pub fn bending_stiffness(&self) -> f64 {
        let a = self.extensional_stiffness();
        if a <= 0.0 {
            return 0.0;
        }
        let sn = self.neutral_axis();
        let s = self.interfaces();
        self.layers
            .iter()
            .enumerate()
            .map(|(i, l)| {
                let offset = 0.5 * (s[i] + s[i + 1]) - sn;
                let h = l.thickness;
                l.youngs_modulus * (h * h * h / 12.0 + h * offset * offset)
            })
            .sum()
    }

    /// Thermal moment per unit width of a temperature profile linear in each layer, N m/m:
    /// M_T = ∫ E a (T − T_ref)(s_n − s) ds with T given at every layer interface (front first).
    /// Positive when the front is hotter in a homogeneous plate (the sign of the two-layer model).
    pub fn thermal_moment_per_width(&self, interface_temperatures: &[f64]) -> f64 {
        let s = self.interfaces();
        let sn = self.neutral_axis();
        let t = interface_temperatures;
        self.layers
            .iter()
            .enumerate()
            .map(|(i, l)| {
                let (a, b) = (s[i], s[i + 1]);
                let ea = l.youngs_modulus * l.expansion_coeff;
                let (ta, tb) = (
                    t[i] - self.reference_temperature,
                    t[i + 1] - self.reference_temperature,
                );
                ea * linear_moment(a, b, sn, ta, tb)
            })
            .sum()
    }

    /// The two-layer panel equivalent to this laminate (the fields `Panel` has), with the
    /// structural and orbital parameters given:
    /// - m = w Σ ρ h and c = Σ ρ c h / Σ ρ h, so that the heat capacity is the laminate's;
    /// - E = A / d (thickness-averaged modulus) and I = w D / E, so that E I = w D;
    /// - K = 1 / Σ(h/k): the two-layer nodes are the two faces, each with half the capacity;
    /// - a such that a E I / d is the moment of a linear profile per kelvin of face-to-face
    ///   difference (the uniform-temperature moment of an unsymmetric layup has no two-layer
    ///   counterpart and is left out there).
    pub fn equivalent_panel(&self, base: &Panel) -> Result<Panel> {
        self.validate()?;
        let d = self.thickness();
        let e = self.extensional_stiffness() / d;
        let w = base.width;
        let inertia = w * self.bending_stiffness() / e;
        let n = self.layers.len();
        // Front at T_ref + 1, back at T_ref, linear through the whole thickness.
        let s = self.interfaces();
        let profile: Vec<f64> = s
            .iter()
            .map(|&z| self.reference_temperature + 1.0 - z / d)
            .collect();
        let uniform = vec![self.reference_temperature; n + 1];
        let per_kelvin =
            w * (self.thermal_moment_per_width(&profile) - self.thermal_moment_per_width(&uniform));
        let panel = Panel {
            emissivity_front: self.emissivity_front,
            emissivity_back: self.emissivity_back,
            absorptivity: self.absorptivity,
            specific_heat: self.heat_capacity() / self.mass_per_area(),
            mass_per_length: w * self.mass_per_area(),
            expansion_coeff: per_kelvin * d / (e * inertia),
            youngs_modulus: e,
            thickness: d,
            conductance: 1.0 / self.thermal_resistance(),
            bending_inertia: inertia,
            ..*base
        };
        Ok(panel)
    }

    /// One homogeneous layer standing for a plain panel: thickness d, the panel's heat capacity
    /// per area, conductivity K d (so that two face nodes are joined by K, as in eq. 2) and the
    /// modulus of a solid plate with the panel's E I, so that a linear profile gives
    /// a E I ΔT / d. The moment scale χ is applied by the thermal model, not here.
    pub fn homogeneous(panel: &Panel) -> Laminate {
        let d = panel.thickness;
        let solid_inertia = panel.width * d * d * d / 12.0;
        Laminate {
            layers: vec![Layer {
                thickness: d,
                conductivity: panel.conductance * d,
                density: panel.mass_per_length / d,
                specific_heat: panel.specific_heat,
                youngs_modulus: panel.youngs_modulus * panel.bending_inertia / solid_inertia,
                expansion_coeff: panel.expansion_coeff,
                name: "panel".into(),
            }],
            emissivity_front: panel.emissivity_front,
            emissivity_back: panel.emissivity_back,
            absorptivity: panel.absorptivity,
            // A homogeneous plate bends only with the gradient, whatever T_ref.
            reference_temperature: REFERENCE_TEMPERATURE,
        }
    }
}

/// ∫ₐᵇ T(s)(s_n − s) ds for T linear from t_a at s = a to t_b at s = b.
pub(crate) fn linear_moment(a: f64, b: f64, sn: f64, ta: f64, tb: f64) -> f64 {
    let h = b - a;
    // ∫ φ_a (s_n − s) = h/2 (s_n − (2a + b)/3), ∫ φ_b (s_n − s) = h/2 (s_n − (a + 2b)/3).
    0.5 * h * (ta * (sn - (2.0 * a + b) / 3.0) + tb * (sn - (a + 2.0 * b) / 3.0))
}

/// A material of the library: the properties of a layer but its thickness, and where they come
/// from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    pub key: &'static str,
    pub name: &'static str,
    pub conductivity: f64,
    pub density: f64,
    pub specific_heat: f64,
    pub youngs_modulus: f64,
    pub expansion_coeff: f64,
    /// The source of every value, as it is quoted in the documentation.
    pub source: &'static str,
}

impl Material {
    /// The properties a layer of this material takes, named as in [`LAYER_FIELDS`] (all but the
    /// thickness).
    pub fn properties(&self) -> impl Iterator<Item = (&'static str, f64)> {
        let values = [self.conductivity, self.density, self.specific_heat];
        let values = values
            .into_iter()
            .chain([self.youngs_modulus, self.expansion_coeff]);
        LAYER_FIELDS[1..].iter().copied().zip(values)
    }

    /// A layer of this material, `thickness` m thick.
    pub fn layer(&self, thickness: f64) -> Layer {
        Layer {
            thickness,
            conductivity: self.conductivity,
            density: self.density,
            specific_heat: self.specific_heat,
            youngs_modulus: self.youngs_modulus,
            expansion_coeff: self.expansion_coeff,
            name: self.key.into(),
        }
    }
}

/// The material library (room-temperature values).
pub const MATERIALS: [Material; 7] = [
    Material {
        key: "aluminium_6061",
        name: "aluminium 6061-T6",
        conductivity: 167.0,
        density: 2700.0,
        specific_heat: 896.0,
        youngs_modulus: 68.9e9,
        expansion_coeff: 23.6e-6,
        source: "ASM Handbook Vol. 2, Properties and Selection: Nonferrous Alloys (ASM \
                 International, 1990), 6061-T6: k 167 W/(m K), ρ 2700 kg/m³, c 896 J/(kg K), \
                 E 68.9 GPa, a 23.6e-6 1/K (20–100 °C).",
    },
    Material {
        key: "titanium_6al4v",
        name: "titanium Ti-6Al-4V (annealed)",
        conductivity: 6.7,
        density: 4430.0,
        specific_heat: 526.3,
        youngs_modulus: 113.8e9,
        expansion_coeff: 8.6e-6,
        source: "Boyer, Welsch & Collings, Materials Properties Handbook: Titanium Alloys \
                 (ASM International, 1994), Ti-6Al-4V annealed: k 6.7 W/(m K), ρ 4430 kg/m³, \
                 c 526.3 J/(kg K), E 113.8 GPa, a 8.6e-6 1/K (20–100 °C).",
    },
    Material {
        key: "cfrp_m55j_qi",
        name: "CFRP M55J/epoxy, quasi-isotropic [0/±45/90]",
        conductivity: 0.7,
        density: 1626.0,
        specific_heat: 825.0,
        youngs_modulus: 113.8e9,
        expansion_coeff: -2.4e-8,
        source: "Derived, not measured: Toray M55J fibre datasheet (E 540 GPa, ρ 1910 kg/m³, \
                 a −1.1e-6 1/K) with an epoxy matrix (E 3.5 GPa, ρ 1200 kg/m³, a 55e-6 1/K) at \
                 fibre volume fraction 0.6; ply E₁ by the rule of mixtures, a₁ and a₂ by \
                 Schapery's formulas (E₂ 6 GPa, G₁₂ 4 GPa, ν₁₂ 0.3 assumed), the quasi-isotropic \
                 E and a by lamination theory; c by mass-weighted mixing (fibre 710, epoxy \
                 1100 J/(kg K)); k through the plies 0.7 W/(m K), a representative value of \
                 carbon/epoxy across the plies, not a handbook figure.",
    },
    Material {
        key: "aluminium_honeycomb",
        name: "aluminium honeycomb core 5052, 3.1 lb/ft³",
        conductivity: 2.56,
        density: 49.7,
        specific_heat: 880.0,
        youngs_modulus: 0.0,
        expansion_coeff: 23.8e-6,
        source: "Hexcel, HexWeb Honeycomb Attributes and Properties: 1/8-5052-.001, density \
                 3.1 lb/ft³ (49.7 kg/m³). Through-thickness k = k of 5052 (138 W/(m K), ASM \
                 Handbook Vol. 2) × relative density 49.7/2680 (conduction along the foil walls \
                 only; radiation and gas in the cells left out); c and a of 5052 (ASM Handbook \
                 Vol. 2: 880 J/(kg K), 23.8e-6 1/K). E in the plane taken as 0: a core carries \
                 no bending stress in sandwich theory.",
    },
    Material {
        key: "kapton",
        name: "Kapton HN polyimide film",
        conductivity: 0.12,
        density: 1420.0,
        specific_heat: 1090.0,
        youngs_modulus: 2.5e9,
        expansion_coeff: 20e-6,
        source: "DuPont, Kapton HN General Specifications (technical data sheet): k 0.12 W/(m K), \
                 ρ 1420 kg/m³, c 1.09 J/(g K), tensile modulus 2.5 GPa, a 20 ppm/°C \
                 (−14 to 38 °C), at 23 °C.",
    },
    Material {
        key: "beryllium_copper",
        name: "beryllium copper C17200, age hardened",
        conductivity: 105.0,
        density: 8250.0,
        specific_heat: 420.0,
        youngs_modulus: 128e9,
        expansion_coeff: 17e-6,
        source: "Materion, Alloy 25 (C17200) strip data sheet, typical values for the \
                 precipitation-hardened temper: k 105 W/(m K), ρ 8.25 g/cm³, c 0.42 J/(g K), \
                 E 128 GPa, a 17 ppm/K (20 to 200 °C).",
    },
    Material {
        key: "stainless_301",
        name: "stainless steel 301, full hard",
        conductivity: 16.2,
        density: 7880.0,
        specific_heat: 500.0,
        youngs_modulus: 193e9,
        expansion_coeff: 17e-6,
        source: "ASM Handbook vol. 1 (1990), wrought austenitic stainless steels, type 301, \
                 room temperature: k 16.2 W/(m K), ρ 7.88 g/cm³, c 0.50 J/(g K), E 193 GPa, \
                 a 17 ppm/K (0 to 100 °C).",
    },
];

/// A material of the library by key.
pub fn material(key: &str) -> Result<&'static Material> {
    MATERIALS.iter().find(|m| m.key == key).ok_or_else(|| {
        let keys: Vec<&str> = MATERIALS.iter().map(|m| m.key).collect();
        Error::invalid(
            "material",
            key,
            &format!("is not in the library ({})", keys.join(", ")),
        )
    })
}

/// A CFRP/honeycomb solar-array substrate with Kapton on the Sun side (the tests' wing).
#[cfg(test)]
pub(crate) fn wing_layup() -> Laminate {
    Laminate {
        layers: vec![
            MATERIALS[4].layer(50e-6),
            MATERIALS[2].layer(0.3e-3),
            MATERIALS[3].layer(20e-3),
            MATERIALS[2].layer(0.3e-3),
        ],
        emissivity_front: 0.8,
        emissivity_back: 0.8,
        absorptivity: 0.9,
        reference_temperature: 293.15,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn slab(e: f64, a: f64, h: f64) -> Layer {
        Layer {
            thickness: h,
            conductivity: 10.0,
            density: 1000.0,
            specific_heat: 900.0,
            youngs_modulus: e,
            expansion_coeff: a,
            name: "x".into(),
        }
    }

    fn laminate(layers: Vec<Layer>) -> Laminate {
        Laminate {
            layers,
            emissivity_front: 0.8,
            emissivity_back: 0.3,
            absorptivity: 0.8,
            reference_temperature: 300.0,
        }
    }

    #[test]
    fn homogeneous_plate_has_the_textbook_stiffness_and_moment() {
        let (e, a, d) = (70e9, 2.5e-5, 0.002);
        let lam = laminate(vec![slab(e, a, d)]);
        assert!((lam.neutral_axis() - d / 2.0).abs() < 1e-18);
        let i = d * d * d / 12.0;
        assert!((lam.bending_stiffness() / (e * i) - 1.0).abs() < 1e-14);
        // Linear profile, front 10 K hotter than the back: M = a E I ΔT / d.
        let m = lam.thermal_moment_per_width(&[310.0, 300.0]);
        assert!((m / (a * e * i * 10.0 / d) - 1.0).abs() < 1e-12, "{m}");
        // Splitting the plate into sublayers changes nothing.
        let split = laminate(vec![slab(e, a, d / 4.0), slab(e, a, 3.0 * d / 4.0)]);
        assert!((split.bending_stiffness() / lam.bending_stiffness() - 1.0).abs() < 1e-13);
        let m2 = split.thermal_moment_per_width(&[310.0, 307.5, 300.0]);
        assert!((m2 / m - 1.0).abs() < 1e-12);
    }

    #[test]
    fn sandwich_stiffness_is_the_faces_parallel_axis_term() {
        // Thin faces t on a core c with no modulus: D = E t (c + t)²/2 + 2 E t³/12.
        let (e, t, c) = (100e9, 0.3e-3, 20e-3);
        let lam = laminate(vec![slab(e, 0.0, t), slab(0.0, 0.0, c), slab(e, 0.0, t)]);
        let want = e * t * (c + t) * (c + t) / 2.0 + 2.0 * e * t * t * t / 12.0;
        assert!((lam.bending_stiffness() / want - 1.0).abs() < 1e-13);
        assert!((lam.neutral_axis() - (c / 2.0 + t)).abs() < 1e-15);
    }

    #[test]
    fn bimetal_curvature_is_timoshenkos() {
        // Timoshenko (1925), uniform heating ΔT of two bonded strips:
        // κ = 6 (a₂ − a₁) ΔT (1 + m)² / (h [3 (1 + m)² + (1 + m n)(m² + 1/(m n))]),
        // m = t₁/t₂, n = E₁/E₂, h = t₁ + t₂; strip 1 on the front.
        for (t1, t2, e1, e2, a1, a2) in [
            (1e-3, 1e-3, 200e9, 70e9, 12e-6, 23e-6),
            (0.4e-3, 1.3e-3, 113e9, 69e9, 8.6e-6, 23.6e-6),
        ] {
            let lam = laminate(vec![slab(e1, a1, t1), slab(e2, a2, t2)]);
            let dt = 50.0;
            let uniform = [300.0 + dt; 3];
            let kappa = lam.thermal_moment_per_width(&uniform) / lam.bending_stiffness();
            let (m, n, h) = (t1 / t2, e1 / e2, t1 + t2);
            let timoshenko = 6.0 * (a2 - a1) * dt * (1.0 + m).powi(2)
                / (h * (3.0 * (1.0 + m).powi(2) + (1.0 + m * n) * (m * m + 1.0 / (m * n))));
            // The back strip expands more: the strip bends away from the back, M_T < 0 here.
            assert!(
                (-kappa / timoshenko - 1.0).abs() < 1e-12,
                "{kappa} vs {timoshenko}"
            );
        }
    }

    #[test]
    fn equivalent_panel_of_a_homogeneous_layer_is_the_panel() {
        let p = Panel::paper();
        let lam = Laminate::homogeneous(&p);
        let q = lam.equivalent_panel(&p).unwrap();
        // E and I are split differently (a solid plate vs the paper's section); E I and the
        // moment per kelvin are the panel's.
        for name in Panel::FIELDS {
            if matches!(name, "youngs_modulus" | "bending_inertia") {
                continue;
            }
            let (a, b) = (p.get(name).unwrap(), q.get(name).unwrap());
            assert!((a - b).abs() <= 1e-12 * a.abs(), "{name}: {a} vs {b}");
        }
        let ei = |x: &Panel| x.youngs_modulus * x.bending_inertia;
        assert!((ei(&q) / ei(&p) - 1.0).abs() < 1e-12);
        assert!((q.moment_per_kelvin() / p.moment_per_kelvin() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn validation_names_the_layer_and_field() {
        let mut lam = laminate(vec![slab(70e9, 1e-5, 1e-3)]);
        lam.layers[0].name = "core".into();
        lam.layers[0].density = -1.0;
        let msg = lam.validate().unwrap_err().to_string();
        assert!(msg.starts_with("layer 'core': density"), "{msg}");
        let lam = laminate(vec![slab(0.0, 1e-5, 1e-3)]);
        assert!(lam.validate().is_err());
        assert!(material("unobtainium").is_err());
        for m in MATERIALS {
            laminate(vec![m.layer(1e-3), MATERIALS[0].layer(1e-3)])
                .validate()
                .unwrap();
        }
    }
}
