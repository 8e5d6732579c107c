//! The scene file schema (DESIGN.md "Scene files"): plain serde types, SI units.
//!
//! Field names are a contract: scripts and `validation/` cases depend on them. Unknown
//! fields are rejected everywhere (`deny_unknown_fields`); values are checked by
//! [`super::validate`].

use serde::{Deserialize, Serialize};

/// One run: geometry, fluid, scheme, time and what to measure.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Name of the scene, used in outputs.
    pub name: String,
    /// Spatial dimension: 2 (3 is parsed and checked; the runner supports 2 and 3).
    pub dimension: usize,
    /// Initial particle spacing Δx \[m\].
    pub dx: f64,
    /// Smoothing kernel and smoothing length.
    pub kernel: KernelSpec,
    /// Fluid properties.
    pub fluid: Fluid,
    /// Body force per unit mass g \[m/s²\] (one component per dimension); zero if absent.
    #[serde(default)]
    pub body_force: Vec<f64>,
    /// Bodies filled with particles on the cell-centred lattice.
    pub bodies: Vec<Body>,
    /// Boundary conditions other than free surfaces (walls, periodic axes, inflow/outflow).
    #[serde(default)]
    pub boundaries: Boundaries,
    /// The scheme and its options.
    pub scheme: Scheme,
    /// End time and time-step rule.
    pub time: TimeSpec,
    /// Quantities recorded as time series.
    #[serde(default)]
    pub probes: Vec<Probe>,
    /// How often probes and frames are written.
    #[serde(default)]
    pub output: OutputSpec,
}

/// Kernel choice: `W(r, h)` with `h = h_over_dx · dx`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KernelSpec {
    /// Kernel family.
    pub kind: KernelKind,
    /// Smoothing length over particle spacing, h / Δx (Qiu 2013 uses 1.5).
    pub h_over_dx: f64,
}

/// Kernel families (see [`crate::kernel`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum KernelKind {
    /// Cubic B-spline, Monaghan & Lattanzio 1985 (Qiu 2013 eq. 8), support 2h.
    CubicSpline,
    /// Wendland C2 (Wendland 1995), support 2h.
    WendlandC2,
}

/// Fluid properties (constant density: the projection scheme keeps ρ fixed).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fluid {
    /// Density ρ \[kg/m³\].
    pub density: f64,
    /// Dynamic viscosity μ \[Pa·s\].
    pub viscosity: f64,
    /// Surface tension coefficient σ \[N/m\]; 0 (default) builds no surface-tension stage.
    #[serde(default)]
    pub surface_tension: f64,
    /// Discretisation of the surface tension (used when σ > 0).
    #[serde(default)]
    pub surface_tension_model: SurfaceTensionModel,
    /// Threshold on the colour gradient, in units of 1/h: normals with
    /// `|∇c| ≤ surface_tension_threshold / h` are dropped (Xu 2016: 0.01, the default).
    #[serde(default = "default_tension_threshold")]
    pub surface_tension_threshold: f64,
    /// Divide σ by the discrete one-sided surface-delta integral of a flat lattice surface
    /// (≈ 0.5; see [`crate::stages::surface_tension::flat_surface_delta`]); false (Xu 2016) by
    /// default.
    #[serde(default)]
    pub surface_tension_normalise: bool,
}

fn default_tension_threshold() -> f64 {
    0.01
}

/// Surface-tension forms (see [`crate::stages::surface_tension`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SurfaceTensionModel {
    /// Hu & Adams 2006 surface stress `Π = σ |∇c| (I/D − n̂ ⊗ n̂)` (Xu 2016).
    #[default]
    HuAdams,
    /// Continuum surface force `σ κ ∇c` (Brackbill, Kothe & Zemach 1992).
    Csf,
    /// Projection ISPH only: the Young–Laplace condition `p = σ κ` as the free-surface
    /// Dirichlet value instead of a force (see [`crate::stages::young_laplace`]).
    YoungLaplace,
}

/// A region filled with particles.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Body {
    /// Fluid or wall particles.
    pub role: Role,
    /// The region.
    pub shape: Shape,
    /// Initial velocity field (zero if absent).
    #[serde(default)]
    pub velocity: InitialVelocity,
    /// Initial pressure field (zero if absent).
    #[serde(default)]
    pub pressure: InitialPressure,
    /// Random displacement of the body's lattice (none if absent): a stress test of how a
    /// scheme copes with a disordered start.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub jitter: Option<Jitter>,
    /// How the shape is filled (the cell-centred lattice if absent).
    #[serde(default, skip_serializing_if = "Packing::is_lattice")]
    pub packing: Packing,
}

/// The arrangement of a body's particles; every particle stands for the volume `Δx^D`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Packing {
    /// The cell-centred lattice `x = c + (i + ½) Δx` (DESIGN.md "Meaning").
    #[default]
    Lattice,
    /// Concentric rings (a 2D circle, or the cross-section of a 3D cylinder stacked at Δx
    /// along its axis): ring `k = 1..n`, `n = round(R/Δx)`, at radius `r_k = (k − ½) R/n`
    /// with `round(2π r_k n/R)` equally spaced particles, so each particle stands for about
    /// `Δx²` of the annulus and the outer ring is a smooth circle half a spacing inside `R`:
    /// a drop (or a pipe's fluid) whose surface has no lattice steps (the steps of a
    /// lattice circle carry a curvature noise of O(1/Δx)). A shell (`inner_radius` > 0)
    /// continues the rings of a disc of radius `inner_radius` outward (spacing
    /// `inner_radius / round(inner_radius/Δx)`), so a pipe wall meets its fluid's rings.
    Rings,
    /// Concentric spherical shells (a 3D sphere; the 3D counterpart of `rings`): shell
    /// `k = 1..n`, `n = round(R/Δx)`, at radius `r_k = (k − ½) R/n` with `round(4π (k − ½)²)`
    /// particles on a golden-angle (Fibonacci) spiral, so each particle stands for about
    /// `Δx³` of the shell and the outer shell is a smooth sphere half a spacing inside `R`.
    Shells,
}

impl Packing {
    /// Whether this is the default lattice (omitted when a scene is written).
    pub fn is_lattice(&self) -> bool {
        *self == Packing::Lattice
    }
}

/// A seeded random displacement of every particle of a body, uniform in the disc (ball in
/// 3D) of radius `fraction · Δx`, drawn from ChaCha8 seeded with `seed` in particle order:
/// the same scene gives the same particles on any machine and thread count. Applied after
/// the overlap check of the lattice (a jittered pair may come closer than Δx/2); the
/// initial velocity and pressure are those of the lattice point.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Jitter {
    /// Largest displacement over Δx, in `[0, 0.5)` (0.1 = 10 % of Δx).
    pub fraction: f64,
    /// Seed of the random stream.
    pub seed: u64,
}

/// What the particles of a body are.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    /// Moving fluid particles.
    Fluid,
    /// Fixed wall particles.
    Wall,
}

/// Shapes; all lengths in metres.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Shape {
    /// Disc (2D): `|x - center| <= radius`.
    Circle {
        /// Centre \[m\].
        center: Vec<f64>,
        /// Radius \[m\].
        radius: f64,
    },
    /// Axis-aligned rectangle (2D) `min <= x <= max`.
    Rectangle {
        /// Lower corner \[m\].
        min: Vec<f64>,
        /// Upper corner \[m\].
        max: Vec<f64>,
    },
    /// Axis-aligned box (3D) `min <= x <= max`.
    Box {
        /// Lower corner \[m\].
        min: Vec<f64>,
        /// Upper corner \[m\].
        max: Vec<f64>,
    },
    /// Ball (3D): `|x - center| <= radius`.
    Sphere {
        /// Centre \[m\].
        center: Vec<f64>,
        /// Radius \[m\].
        radius: f64,
    },
    /// Circular cylinder (3D) along `axis`: the points whose distance ρ from the axis line
    /// through `center` is at most `radius` and whose coordinate along `axis` lies within
    /// `length / 2` of the centre's. With `inner_radius` > 0 a cylindrical shell
    /// (`inner_radius < ρ <= radius`): the wall body of a pipe around a fluid cylinder of
    /// radius `inner_radius`.
    Cylinder {
        /// Centre of the cylinder (the middle of its axis) \[m\].
        center: Vec<f64>,
        /// The axis the cylinder runs along (0, 1 or 2).
        axis: usize,
        /// Outer radius \[m\].
        radius: f64,
        /// Length along `axis` \[m\].
        length: f64,
        /// Inner radius of a shell \[m\] (0, a solid cylinder, if absent).
        #[serde(default, skip_serializing_if = "is_zero")]
        inner_radius: f64,
    },
}

/// Whether a length is zero (an omitted optional length).
fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// Initial velocity field.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum InitialVelocity {
    /// u = 0.
    #[default]
    Zero,
    /// `u(x) = gradient · x + offset`; row i of `gradient` gives component i \[1/s\], offset \[m/s\].
    Affine {
        /// Velocity gradient ∂u_i/∂x_j, row i = component i \[1/s\].
        gradient: Vec<Vec<f64>>,
        /// Constant part \[m/s\].
        offset: Vec<f64>,
    },
}

/// Initial pressure field.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum InitialPressure {
    /// p = 0.
    #[default]
    Zero,
    /// `p(x) = value + ½ (x − c)ᵀ hessian (x − c)` \[Pa\].
    Quadratic {
        /// Centre c \[m\].
        center: Vec<f64>,
        /// Value at the centre \[Pa\].
        value: f64,
        /// Hessian \[Pa/m²\] (symmetric).
        hessian: Vec<Vec<f64>>,
    },
    /// `p = ρ g · (x − surface_point)` with the scene's body force g: zero at `surface_point`.
    Hydrostatic {
        /// A point on the free surface \[m\].
        surface_point: Vec<f64>,
    },
}

/// Boundary conditions beyond free surfaces. Empty (the default) builds no boundary stage.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Boundaries {
    /// Periodic axes (0 = x, 1 = y, 2 = z) with their period.
    #[serde(default)]
    pub periodic: Vec<PeriodicAxis>,
    /// Plane no-slip walls (none and no wall body: no wall stage is built).
    #[serde(default)]
    pub walls: Vec<Wall>,
    /// How walls are represented.
    #[serde(default)]
    pub wall_model: WallModel,
    /// A uniform-velocity inlet (with `outflow`; none: no open-boundary stage is built).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inflow: Option<Inflow>,
    /// An outlet downstream of `inflow`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outflow: Option<Outflow>,
}

/// A uniform-velocity inlet: the plane `x[axis] = position`, the flow entering towards
/// `+axis` at `velocity` through a buffer of particles upstream of the plane (the fluid's
/// first lattice column repeated upstream over the kernel support), moving at `velocity`
/// and turned into fluid particles as they cross the plane.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Inflow {
    /// Axis of the flow (0 = x).
    pub axis: usize,
    /// Position of the inlet plane \[m\].
    pub position: f64,
    /// Inflow speed U along `+axis` \[m/s\] (> 0).
    pub velocity: f64,
}

/// An outlet: the plane `x[axis] = position`; fluid particles crossing it join a buffer
/// downstream that keeps their normal velocity and zero pressure (a Dirichlet `p = 0`
/// outlet), and leave when they are a kernel support past the plane.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Outflow {
    /// Axis of the flow (the inflow's).
    pub axis: usize,
    /// Position of the outlet plane \[m\] (downstream of the inlet).
    pub position: f64,
}

/// A plane no-slip wall at rest, normal to a coordinate axis: `x[axis] = position`, the
/// fluid on `fluid_side`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Wall {
    /// Axis of the wall normal (0 = x, 1 = y, 2 = z).
    pub axis: usize,
    /// Position of the wall plane on that axis \[m\].
    pub position: f64,
    /// The side of the plane the fluid is on.
    pub fluid_side: Side,
}

/// A side of a plane normal to an axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// Coordinates above the plane (`x[axis] > position`).
    Above,
    /// Coordinates below the plane (`x[axis] < position`).
    Below,
}

/// Wall representation.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WallModel {
    /// Mirror particles rebuilt every step (Qiu 2013 §2.4.2): every fluid particle within the
    /// kernel support of a wall is reflected across it, with velocity `−u` (no slip) and its
    /// own pressure; near a corner it is reflected across both walls too.
    #[default]
    Mirror,
    /// Fixed dummy particles filling the kernel support behind each wall plane on the
    /// fluid's lattice, and the particles of every wall body (`role: wall`), with the
    /// generalised wall condition of Adami, Hu & Adams 2012: velocity `−ũ` and pressure
    /// `(Σ p_f W + ρ g·Σ r_wf W)/Σ W` extrapolated from the fluid. Wall bodies need it.
    Dummy,
}

/// One periodic axis: positions wrap into `[min, max)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PeriodicAxis {
    /// Axis index (0 = x).
    pub axis: usize,
    /// Lower end of the period \[m\].
    pub min: f64,
    /// Upper end of the period \[m\].
    pub max: f64,
}

/// Particle scheme.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Scheme {
    /// Projection ISPH (Qiu 2013 §2.2–2.6; Cummins & Rudman 1999; Shao & Lo 2003).
    Isph(IsphOptions),
    /// Weakly compressible SPH (Xu 2016 with the standard forms of CASES.md erratum 6):
    /// continuity equation, Tait equation of state, kick-drift-kick integration.
    Wcsph(WcsphOptions),
    /// Moving particle semi-implicit (Koshizuka & Oka 1996; Lan, Zhao & Wan 2022 eqs. 3–9
    /// with the mixed source of Lee et al. 2011; MPS.md): number-density weights instead of
    /// a kernel, a pressure Poisson equation per step, multi-layer wall particles.
    Mps(MpsOptions),
    /// Optimal-transportation meshfree method (Li, Habbal & Ortiz 2010; Zhou et al. 2021;
    /// OTM.md): the body triangulated at set-up, nodes and material points coupled by local
    /// max-entropy shape functions, surface tension as the boundary's energy ([`crate::otm`]).
    Otm(OtmOptions),
}

/// Options of the optimal-transportation meshfree scheme (see [`crate::otm`]): one fluid
/// body meshed at the scene's `dx` (a circle or a rectangle in 2D, a sphere solved
/// axisymmetric in 3D); the scene's `kernel` is used only by the probes' kernel-weighted
/// averages.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OtmOptions {
    /// Sound speed c₀ of the equation of state `p = c₀² (ρ − ρ₀)` \[m/s\].
    pub sound_speed: f64,
    /// Locality γ of the LME shape functions, `β = γ / dx²` (dimensionless; 1.5 if absent).
    #[serde(default = "default_locality")]
    pub locality: f64,
    /// Material points per triangle (absent: `centroid` in 2D, `degree_two` in 3D, where
    /// one point per triangle does not hold a uniform pressure next to the axis).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quadrature: Option<Quadrature>,
    /// Which stresses' nodal forces take the consistent integration of
    /// [`crate::otm::integration`] (absent: `point`, Zhou's plain point sums).
    #[serde(default, skip_serializing_if = "Integration::is_point")]
    pub integration: Integration,
    /// Where the material points' density comes from (absent: `material`, Zhou's).
    #[serde(default, skip_serializing_if = "Density::is_material")]
    pub density: Density,
}

/// Where the OTM material points' density `ρ_p = m_p / V_p` (and through the equation of
/// state their pressure) comes from ([`crate::otm::step`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Density {
    /// Each point's own volume, `V_p ← det(ΔF_p) V_p` (Li et al. 2010, Zhou 2021).
    #[default]
    Material,
    /// Then projected through the nodes every step: `ρ_a = m_a / Σ_p N_a V_p`,
    /// `ρ_p = Σ_a N_a ρ_a`, `V_p = m_p / ρ_p`. It removes the volume noise the nodes cannot
    /// move (two points per node in the plane), which otherwise grows in a long shear. For
    /// confined flows: on the drop on a plate (free surface, surface tension) a boundary
    /// point left its nodes' hull between 0.7 and 3.6 s (docs/notes/otm.md).
    Nodal,
}

impl Density {
    /// True for Zhou's per-point volumes (the default, left out of a written scene).
    pub fn is_material(&self) -> bool {
        *self == Density::Material
    }

    /// The option's key in the scene file.
    pub fn key(&self) -> &'static str {
        match self {
            Density::Material => "material",
            Density::Nodal => "nodal",
        }
    }
}

/// How the OTM nodal forces `−Σ_p V_p σ_p ∇N_a(x_p)` integrate over the material points
/// ([`crate::otm::integration`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Integration {
    /// The plain point sums (Zhou 2021, Li et al. 2010).
    #[default]
    Point,
    /// The viscous stress's forces with the corrected test gradients, the pressure's plain:
    /// long shear flows (the sheared arrangement of points among nodes otherwise loses the
    /// quadrature's consistency and the viscous force with it).
    ConsistentViscous,
    /// Both stresses' forces with the corrected test gradients: a linear pressure field (a
    /// hydrostatic body) gives exact nodal forces. The pressure–volume pair is then no
    /// longer energy-consistent: a long Re = 40 channel diverged (docs/notes/otm.md).
    Consistent,
}

impl Integration {
    /// True for the plain point sums (the default, left out of a written scene).
    pub fn is_point(&self) -> bool {
        *self == Integration::Point
    }

    /// The option's key in the scene file.
    pub fn key(&self) -> &'static str {
        match self {
            Integration::Point => "point",
            Integration::ConsistentViscous => "consistent_viscous",
            Integration::Consistent => "consistent",
        }
    }
}

/// Where an OTM body's material points sit in each triangle of its set-up mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Quadrature {
    /// One point at the centroid with the triangle's area (Zhou 2021 §2.1).
    Centroid,
    /// Three points at the barycentric (2/3, 1/6, 1/6) points, a third of the area each
    /// (the degree-two rule).
    DegreeTwo,
}

fn default_locality() -> f64 {
    1.5
}

impl Scheme {
    /// The scheme's key in the scene file (`isph`, `wcsph`).
    pub fn key(&self) -> &'static str {
        match self {
            Scheme::Isph(_) => "isph",
            Scheme::Wcsph(_) => "wcsph",
            Scheme::Mps(_) => "mps",
            Scheme::Otm(_) => "otm",
        }
    }
}

/// Options of the moving particle semi-implicit scheme (see [`crate::mps`]). Lengths are
/// in units of the initial spacing l0 = `dx`; the scene's `kernel` is used only by the
/// optional shifting and the probes' kernel-weighted averages. Walls are always MPS wall
/// particles (`boundaries.wall_model` must stay `mirror`, its default).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MpsOptions {
    /// Weight function w(r) of every operator.
    #[serde(default)]
    pub weight: MpsWeight,
    /// Radius of each operator in units of l0 (default: Lan's 2.1 / 2.1 / 4.1 for the `lan`
    /// weight, Koshizuka & Oka's 2.1 / 2.1 / 3.1 for `classic`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radii: Option<MpsRadii>,
    /// Weight γ ∈ [0, 1] of the number-density term of the mixed PPE source (Lee et al.
    /// 2011; Lan eq. 4): `(1 − γ)(ρ/Δt)⟨∇·u*⟩ − γ (ρ/Δt²)(n* − n0)/n0`. Lan prints 0.99; the
    /// other MLParticle-SJTU papers use 0.01.
    pub gamma: f64,
    /// Quasi-compressibility α \[1/Pa\] (Tanaka & Masunaga 2010): `(ρ α/Δt²) P_i` on the
    /// left of the PPE; 0 (the default) for none. Koshizuka's sample uses 0.45e-9.
    #[serde(default)]
    pub compressibility: f64,
    /// Free-surface detection.
    #[serde(default)]
    pub free_surface: MpsFreeSurface,
    /// Form of the pressure gradient of the velocity correction.
    #[serde(default)]
    pub pressure_gradient: MpsGradient,
    /// Form of the velocity divergence of the PPE source.
    #[serde(default)]
    pub divergence: MpsDivergence,
    /// Set negative pressures to zero before the correction (Koshizuka's sample code; off in
    /// channels, where the pressure level is arbitrary).
    #[serde(default)]
    pub clip_negative_pressure: bool,
    /// Particle shifting after the correction, the other schemes' stage (none if absent):
    /// not part of Lan's MPS; the shift's neighbour sums use the scene's kernel.
    #[serde(default)]
    pub shifting: Shifting,
    /// Time integration of the viscous term: explicit (Lan, the default) or backward Euler
    /// (`mps::viscosity::ImplicitPredictor`: no viscous time-step limit; not Lan's).
    #[serde(default)]
    pub viscosity: ViscousIntegration,
    /// Pressure Poisson solver (CG: the matrix is symmetric positive definite).
    pub ppe: PpeOptions,
}

/// Weight functions of the MPS operators.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MpsWeight {
    /// Lan 2022 eq. 3 (Zhang 2014): `re/(0.85 r + 0.15 re) − 1`, finite at r = 0.
    #[default]
    Lan,
    /// Koshizuka & Oka 1996: `re/r − 1`.
    Classic,
}

/// Operator radii of MPS in units of l0 (each at least 1: the nearest neighbours).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MpsRadii {
    /// Particle number density and the free-surface test.
    pub number_density: f64,
    /// Gradient and divergence.
    pub gradient: f64,
    /// Laplacian (viscosity and the PPE).
    pub laplacian: f64,
}

impl MpsWeight {
    /// The weight's default radii (MPS.md): Lan 2.1 / 2.1 / 4.1, classic 2.1 / 2.1 / 3.1.
    pub fn default_radii(self) -> MpsRadii {
        let laplacian = match self {
            MpsWeight::Lan => 4.1,
            MpsWeight::Classic => 3.1,
        };
        MpsRadii { number_density: 2.1, gradient: 2.1, laplacian }
    }
}

impl MpsOptions {
    /// The operator radii in units of l0: the scene's, or the weight's defaults.
    pub fn radii(&self) -> MpsRadii {
        self.radii.unwrap_or_else(|| self.weight.default_radii())
    }
}

/// Free-surface detection of MPS.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MpsFreeSurface {
    /// β of the classic test `n* < β n0` (default 0.97 in 2D, 0.98 in 3D).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub beta: Option<f64>,
    /// The auxiliary criterion of Zhang & Wan (Lan's ref. 15): surface if `n* < 0.8 n0`, or
    /// if `n* ≤ β n0` and `|F_i| > 0.9 |F|0` with `F_i = (d/n0) Σ (r_i − r_j) w_ij/|r_ij|`
    /// and `|F|0` its value at a flat surface of the initial lattice.
    #[serde(default)]
    pub auxiliary: bool,
}

/// Velocity divergence of the MPS PPE source.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MpsDivergence {
    /// Lan eq. 7: `(d/n0) Σ (u_j − u_i)·r_ij w_ij/|r_ij|²`, exact for linear fields on the
    /// undeformed lattice only.
    #[default]
    Lan,
    /// `tr(Σ (u_j − u_i) ⊗ r_ij w/r² · [Σ r_ij ⊗ r_ij w/r²]⁻¹)`: the corrective matrix of
    /// the gradient applied to the divergence, exact for linear fields on any arrangement.
    Corrected,
}

/// Pressure gradient of the MPS velocity correction.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MpsGradient {
    /// Lan eq. 6: `(d/n0) Σ (P_j − P_i) r_ij w_ij/|r_ij|²`.
    #[default]
    Lan,
    /// Koshizuka & Oka 1996: `P_j − P̂_i` with `P̂_i` the smallest pressure of the
    /// neighbourhood (the particle included): every pair repels, which stabilises.
    Minimum,
    /// Lan's difference premultiplied by the corrective matrix
    /// `C_i = [(d/n0) Σ w r⊗r/|r|²]⁻¹` (exact for linear pressure fields; the plain form
    /// where the matrix is near singular).
    Corrected,
}

/// Options of the weakly compressible scheme (see [`crate::wcsph`]).
///
/// The reference density ρ₀ is `fluid.density`; every particle has the mass
/// `m = ρ₀ Δx^D`. Pressure follows the Tait equation `p = B ((ρ/ρ₀)^γ − 1)`,
/// `B = ρ₀ c₀² / γ` (Monaghan 1994, J. Comput. Phys. 110:399, eq. 3.3; Batchelor 1967).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WcsphOptions {
    /// Artificial speed of sound c₀ \[m/s\] (about 10 × the largest flow speed keeps
    /// density variations near 1 %).
    pub sound_speed: f64,
    /// Exponent γ of the Tait equation (7 for water, the default).
    #[serde(default = "default_gamma")]
    pub gamma: f64,
    /// Monaghan artificial viscosity (none if absent).
    #[serde(default)]
    pub artificial_viscosity: Option<ArtificialViscosity>,
    /// Molteni–Colagrossi density diffusion coefficient δ (none if absent; 0.1 is usual).
    #[serde(default)]
    pub density_diffusion: Option<f64>,
    /// Velocity divergence of the continuity equation.
    #[serde(default)]
    pub continuity: ContinuityForm,
    /// Particle shifting after the second half kick (none if absent): the ISPH stage
    /// ([`crate::stages::shifting`]), with its free-surface scaling on `div r` against the
    /// threshold `D − ½` (1.5 in 2D, Qiu eq. 16 as corrected).
    #[serde(default)]
    pub shifting: Shifting,
}

/// Velocity divergence of the weakly compressible continuity equation.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ContinuityForm {
    /// Liu & Liu 2003 eq. 4.32: `dρ_a/dt = Σ_b m u_ab·∇_aW_ab`.
    #[default]
    Standard,
    /// `dρ_a/dt = −ρ_a tr(G_a M_a⁻¹)`, `G_a = Σ_b V_b (u_b − u_a) ⊗ ∇_aW_ab`,
    /// `M_a = Σ_b V_b (r_b − r_a) ⊗ ∇_aW_ab` (Bonet & Lok 1999 kernel-gradient correction):
    /// exact for linear velocity fields, also where the support is truncated by a free
    /// surface.
    Corrected,
}

fn default_gamma() -> f64 {
    7.0
}

/// Monaghan 1992 artificial viscosity (Annu. Rev. Astron. Astrophys. 30:543, eq. 4.1):
/// `Π_ab = (−α c₀ μ_ab + β μ_ab²) / ρ̄_ab` for approaching pairs (`u_ab·r_ab < 0`),
/// `μ_ab = h u_ab·r_ab / (r² + 0.01 h²)`, else 0.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArtificialViscosity {
    /// α (linear, shear and bulk viscosity; Xu 2016 uses 1 for impacts, 0.01–0.1 is usual
    /// without impacts).
    pub alpha: f64,
    /// β (quadratic, against interpenetration at shocks; Xu 2016 uses 2 for impacts).
    #[serde(default)]
    pub beta: f64,
}

/// Options of the projection ISPH scheme.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IsphOptions {
    /// Pressure Poisson solver.
    pub ppe: PpeOptions,
    /// Free-surface threshold on `div r` (Qiu eq. 16 corrected): a particle with
    /// `div r` below it is on the free surface. Default `D − ½`: 1.5 in 2D (Qiu), 2.5 in
    /// 3D (`div r` is about D in the bulk and about D − 1 on a flat surface; public 3D codes
    /// use 2.25–2.75; WCSPH's and MPS's shifting use the same `D − ½`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub free_surface_threshold: Option<f64>,
    /// Particle shifting (none if absent).
    #[serde(default)]
    pub shifting: Shifting,
    /// Form of the pressure gradient in the correction step.
    #[serde(default)]
    pub pressure_gradient: PressureGradient,
    /// Form of the velocity divergence on the PPE right-hand side.
    #[serde(default)]
    pub divergence: Divergence,
    /// Coefficient α ∈ [0, 1] of the density-relaxation term added to the PPE source
    /// (0, the default: none; see `isph::projection::PpeAssemble`). A divergence-free
    /// projection does not restore a drifted particle density; in a closed or periodic
    /// domain the volume is fixed, but through an open boundary the fluid can compress.
    #[serde(default)]
    pub density_relaxation: f64,
    /// Time integration of the viscous term.
    #[serde(default)]
    pub viscosity: ViscousIntegration,
    /// Discrete operator of the viscous term.
    #[serde(default)]
    pub viscous_operator: ViscousOperator,
    /// The Dirichlet value of the free-surface particles (default `zero`, Qiu eq. 16).
    #[serde(default, skip_serializing_if = "FreeSurfacePressure::is_zero")]
    pub free_surface_pressure: FreeSurfacePressure,
}

impl IsphOptions {
    /// The free-surface threshold in a `d`-dimensional scene: the scene's, else `d − ½`.
    pub fn free_surface_threshold(&self, d: usize) -> f64 {
        self.free_surface_threshold.unwrap_or(d as f64 - 0.5)
    }
}

/// Discrete viscous operator of the ISPH predictor (Qiu 2013 eq. 4).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ViscousOperator {
    /// Shao & Lo 2003 (Qiu eq. 13): `ν Σ_b 2 V_b (r_ab·∇_aW_ab)/(r² + η²) u_ab`. The pair
    /// force lies along `u_ab`, so it is not central: where a free surface truncates the
    /// support it exerts a torque even on a rigid rotation (measured on `rotating_square`,
    /// μ = 1000 Pa s: −22 % angular momentum by t = 0.05 s).
    #[default]
    ShaoLo,
    /// Monaghan–Cleary (Cleary 1998, Appl. Math. Model. 22:981; reviewed in Monaghan 2005,
    /// Rep. Prog. Phys. 68:1703): `2(D+2) ν Σ_b V_b (u_ab·r_ab)/(r² + η²) ∇_aW_ab`.
    /// A Taylor expansion over a full support gives `ν (∇²u + 2∇(∇·u))`, so `ν ∇²u` for
    /// divergence-free flow. Central, antisymmetric pair forces: it conserves linear and
    /// angular momentum exactly and vanishes for rigid motion, with or without a free
    /// surface. Explicit integration only; its adaptive viscous step limit is `D/(D+2)`
    /// times Shao–Lo's (its largest eigenvalue is `(D+2)/D` times larger).
    MonaghanCleary,
    /// Second-order consistent (Fatehi & Manzari 2011, Comput. Math. Appl. 61:482): the
    /// Hessian fitted from the second differences with the kernel-corrected gradient
    /// subtracted and its error solved for, exact for quadratic fields on any arrangement
    /// (`isph::consistent_viscosity`). Removes the Shao–Lo operator's moment error, which
    /// does not shrink with Δx. Explicit integration only; not momentum-conserving.
    Consistent,
}

impl ViscousOperator {
    /// The operator's name in a scene file (its serde name).
    pub fn scene_name(self) -> &'static str {
        match self {
            ViscousOperator::ShaoLo => "shao_lo",
            ViscousOperator::MonaghanCleary => "monaghan_cleary",
            ViscousOperator::Consistent => "consistent",
        }
    }
}

/// Time integration of the viscous term of the predictor (Qiu 2013 eq. 4).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ViscousIntegration {
    /// Forward Euler (Qiu): bound by the viscous limit `Δt ≤ α_d ρ h²/μ` (eq. 18).
    #[default]
    Explicit,
    /// Backward Euler, one sparse solve per component; no viscous time-step limit.
    Implicit,
}

/// The pressure the projection imposes on its free-surface particles.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FreeSurfacePressure {
    /// `p = 0` on the particles themselves (Qiu 2013 eq. 16), which sit about Δx/2
    /// inside the surface of the volume they represent.
    #[default]
    Zero,
    /// `p = 0` at the surface, Δx/2 outside the particles: each free-surface particle
    /// carries `p_a = (Δx/2) n̂_a·∇p_a`, the linear extrapolation of the previous step's
    /// pressure (`stages::surface_extrapolation`).
    Extrapolated,
}

impl FreeSurfacePressure {
    /// Whether this is the default (`zero`, left out of a written scene).
    pub fn is_zero(&self) -> bool {
        *self == FreeSurfacePressure::Zero
    }
}

/// Velocity-divergence operator of the PPE source term.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Divergence {
    /// Qiu 2013 eq. 10: `Σ_b V_b (u_b − u_a)·∇_aW_ab`.
    #[default]
    Standard,
    /// Kernel-gradient corrected (Bonet & Lok 1999): `tr(G_a M_a⁻¹)` with
    /// `G_a = Σ_b V_b (u_b − u_a) ⊗ ∇_aW_ab`, `M_a = Σ_b V_b (r_b − r_a) ⊗ ∇_aW_ab`;
    /// exact for linear velocity fields on any particle arrangement.
    Corrected,
}

/// Pressure Poisson solver options (DESIGN.md "The solver").
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PpeOptions {
    /// Linear solver.
    pub solver: PpeSolver,
    /// Relative residual tolerance ‖b − Ax‖/‖b‖ (Qiu 2013 uses 1e-3).
    pub tolerance: f64,
    /// Iteration cap of the Krylov solvers.
    pub max_iterations: usize,
    /// Preconditioner of the Krylov solvers (default Jacobi).
    #[serde(default)]
    pub preconditioner: Preconditioner,
    /// Most solves between rebuilds of the two-level preconditioner's coarse space
    /// (aggregates and factorised coarse matrix, kept across steps: `linalg/two_level.rs`; a
    /// solve that shows it degraded brings the rebuild forward); default 25, at least 1.
    /// Unused with Jacobi.
    #[serde(default = "default_coarse_refresh")]
    pub coarse_refresh: usize,
}

fn default_coarse_refresh() -> usize {
    crate::linalg::two_level::DEFAULT_REFRESH
}

/// Preconditioners of the Krylov PPE solvers.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Preconditioner {
    /// `diag(A)⁻¹`.
    #[default]
    Jacobi,
    /// Jacobi plus a coarse-space correction by aggregation (`linalg/two_level.rs`): for long
    /// domains, whose smooth pressure modes Jacobi leaves to the Krylov iterations. A
    /// system with no Dirichlet row keeps Jacobi.
    TwoLevel,
}

/// Linear solvers for the PPE.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PpeSolver {
    /// BiCGSTAB with a Jacobi preconditioner (Qiu 2013).
    Bicgstab,
    /// Conjugate gradient with a Jacobi preconditioner (the matrix is SPD for equal volumes).
    Cg,
    /// Sparse LU factorisation (faer).
    Direct,
}

/// Particle shifting (Qiu 2013 §2.6).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Shifting {
    /// No shifting.
    #[default]
    None,
    /// Xu et al. 2009 (Qiu eqs. 20–21): `δr = C Δt u_max Σ (r̄²/r²) n_ab`.
    Xu {
        /// C, 0.01–0.1 (Qiu uses 0.02).
        coefficient: f64,
        /// Weight every term of the sum and of the mean distance r̄ by `(1 − r²/(2h)²)²`,
        /// which makes the shift continuous in the positions (false: Xu as published).
        /// As published, the shift jumps whenever a neighbour crosses the kernel support
        /// (a 1/r² term appears, and r̄ averages over one more pair), and a bit-level change
        /// of the positions then moves a periodic channel by 1e-3 of u_max at Re = 400
        /// (docs/notes/shifting.md, "Xu shifting is discontinuous at the support").
        #[serde(default, skip_serializing_if = "std::ops::Not::not")]
        smooth: bool,
    },
    /// Lind et al. 2012 Fickian shifting: `δr = −A h |u| Δt ∇C`.
    Fickian {
        /// A, 1–6 (Lind uses 2).
        coefficient: f64,
    },
}

/// Pressure-gradient operator of the correction step.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PressureGradient {
    /// Qiu 2013 eq. 15: `Σ V_b (p_a + p_b) ∇W / ρ` (momentum conserving).
    #[default]
    Symmetric,
    /// `Σ V_b (p_b − p_a) ∇W / ρ` (zero-order consistent).
    Difference,
    /// The difference form with the kernel-gradient correction (Bonet & Lok 1999, eq. 43;
    /// Randles & Libersky 1996): `L_a Σ V_b (p_b − p_a) ∇W / ρ`,
    /// `L_a = (Σ V_b (r_b − r_a) ⊗ ∇_aW_ab)⁻¹`, first-order consistent also where a free
    /// surface truncates the kernel support (the plain form gives about half the gradient
    /// on the surface row); the plain form where the matrix is singular.
    Corrected,
}

/// End time and time-step rule.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeSpec {
    /// End time \[s\].
    pub end: f64,
    /// Step rule.
    pub step: TimeStep,
    /// Stop before `end` once the flow is steady (absent: run to `end`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steady: Option<SteadyStop>,
}

/// A steady-state stop (`time.steady`): after each probe sample at `t ≥ max(after,
/// 2 window)`, the mean of every selected quantity of one probe over the last `window`
/// seconds, `m₁`, is compared with its mean over the `window` before, `m₀`; the run ends
/// (as reached) at the first sample where `‖m₁ − m₀‖₂ ≤ tolerance ‖m₁‖₂` over the selected
/// quantities. Two window means, not two samples, because a particle sample is noisy; a
/// non-finite mean (an empty bin) means "not steady".
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SteadyStop {
    /// Output key of the probe (`velocity_profile_1`: the second `velocity_profile`).
    pub probe: String,
    /// Quantities of the probe compared: those whose name starts with this (`u_`: the
    /// velocity bins of a profile); all of them when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quantities: Option<String>,
    /// Averaging window \[s\].
    pub window: f64,
    /// Relative change of the window means at which the flow counts as steady.
    pub tolerance: f64,
    /// No stop before this time \[s\] (e.g. before the flow can have reached the probe).
    #[serde(default)]
    pub after: f64,
}

/// Time-step rule.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum TimeStep {
    /// Fixed Δt \[s\].
    Fixed(f64),
    /// Adaptive (Qiu eqs. 17–19): `Δt = min(α_c h/u_max, α_d ρ h²/μ)`, capped at `max`.
    Adaptive {
        /// α_c (Qiu: 0.2).
        #[serde(default = "default_alpha")]
        cfl: f64,
        /// α_d (Qiu: 0.2).
        #[serde(default = "default_alpha")]
        viscous: f64,
        /// Upper bound on Δt \[s\] (used while the fluid is at rest).
        max: f64,
    },
}

fn default_alpha() -> f64 {
    0.2
}

/// A probe: a quantity recorded every `output.probe_every` steps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Probe {
    /// Ellipse semi-axes of the fluid: `a_moment`, `b_moment` (2 √⟨x²⟩ about the centroid),
    /// `a_extent`, `b_extent` (half the extent of the particles), `x_centroid`, `y_centroid`.
    EllipseAxes {},
    /// Pressure at a point by a Shepard average over the kernel support: `p` \[Pa\].
    PressureAt {
        /// The point \[m\].
        point: Vec<f64>,
    },
    /// Mean pressure `p` \[Pa\] of the fluid particles within `radius` of `center` (a
    /// drop's inside pressure, averaged over many particles instead of one support), and
    /// their number `count`.
    MeanPressure {
        /// Centre of the ball (disc in 2D) \[m\].
        center: Vec<f64>,
        /// Its radius \[m\].
        radius: f64,
    },
    /// The least-squares pressure gradient over the fluid particles within `radius` of
    /// `center` (`p ≈ p̄ + ∇p · (x − x̄)`, each particle weighted by its volume):
    /// `dp_dx`, `dp_dy` (and `dp_dz` in 3D) \[Pa/m\] (a resting drop's hydrostatic
    /// gradient, −ρg), and their number `count`.
    PressureGradient {
        /// Centre of the ball (disc in 2D) \[m\].
        center: Vec<f64>,
        /// Its radius \[m\].
        radius: f64,
    },
    /// Ellipsoid semi-axes of the fluid (3D): `a_moment`, `b_moment`, `c_moment`
    /// (√(5⟨x_i²⟩) about the centroid along x, y, z: the semi-axes of the uniform ellipsoid
    /// with the same second moments) \[m\], and `x_centroid`, `y_centroid`, `z_centroid`.
    EllipsoidAxes {},
    /// Total kinetic energy per unit depth `e` \[J/m in 2D\].
    KineticEnergy {},
    /// Linear momentum components `px`, `py`(, `pz`) and angular momentum `lz` (3D also
    /// `lx`, `ly`) about the origin.
    Momentum {},
    /// Particle disorder: `min_pair_over_dx`, `close_fraction` (neighbour closer than 0.5 Δx).
    Disorder {},
    /// Solver state: the free-surface particle count `free_surface_count`, the last PPE
    /// solve's `iterations` and relative residual `residual` (‖b − A p‖ / ‖b‖), and `p_max`,
    /// the largest |p| over the fluid \[Pa\]. A projection that turns unstable shows here
    /// first: p_max growing several times per step with the iterations while the flow is
    /// still smooth (docs/notes/paper-preset-divergence-dx0005.md).
    Solver {},
    /// Mass balance of an open channel (`boundaries.inflow`): the fluid mass in the domain
    /// `mass` and the cumulative masses that entered, `inflow`, and left, `outflow`
    /// \[kg, per metre of depth in 2D\].
    MassBalance {},
    /// Largest particle speed `u_max` and root-mean-square speed `u_rms` \[m/s\] (spurious
    /// currents of a drop at rest).
    MaxSpeed {},
    /// Shape of a drop: `clusters`, the number of separate bodies (particles linked by
    /// pairs closer than 2 Δx), and `r_max`, the largest distance of a particle from the
    /// centroid \[m\].
    DropShape {},
    /// Velocity profile across a channel: the fluid in `range` along `axis` (optionally only
    /// where `slab.axis` lies in `slab.range`) is split into equal bins; each bin
    /// records the mean position `y_###` \[m\] and the mean velocity component `u_###`
    /// \[m/s\] of its particles (NaN when empty), `###` the zero-padded bin index.
    VelocityProfile {
        /// Axis across the profile (1 = y for a channel along x).
        axis: usize,
        /// Velocity component recorded (0 = u_x).
        component: usize,
        /// Extent of the profile along `axis` \[m\].
        range: [f64; 2],
        /// Number of bins (1–999); absent: one per particle row, `round((range[1] − range[0]) / Δx)`.
        #[serde(default)]
        bins: Option<usize>,
        /// Restrict to particles with `x[slab.axis]` in `slab.range` (all if absent).
        #[serde(default)]
        slab: Option<Slab>,
    },
    /// Velocity profile across a pipe (3D): the fluid within `radius` of the axis line
    /// through `center` along `axis` is split into equal bins of the distance ρ from that
    /// line; each bin records the mean distance `r_###` \[m\] and the mean velocity
    /// component `u_###` \[m/s\] of its particles (NaN when empty).
    RadialProfile {
        /// The pipe's axis (0 = x).
        axis: usize,
        /// A point of the axis line \[m\].
        center: Vec<f64>,
        /// Outer edge of the last bin \[m\] (the pipe's radius).
        radius: f64,
        /// Velocity component recorded (0 = u_x, the flow along a pipe on x).
        component: usize,
        /// Number of bins (1–999); absent: one per Δx, `round(radius / Δx)`.
        #[serde(default)]
        bins: Option<usize>,
    },
    /// Spreading of drops on a plane (an impact on a wall or a film; Xu 2016 §3.2–3.3): of
    /// the fluid on the positive side of the plane `x[axis] = position` (centres with
    /// `s = x[axis] − position > 0`), about the axis through its in-plane centroid,
    /// `diameter` = 2 (largest in-plane distance ρ of a particle with `s ≤ layer` + Δx/2),
    /// the wetted (contact) diameter \[m\]; `width` = 2 (largest ρ + Δx/2) over all of it,
    /// the spread width seen from above (a lamella lifted off the plane counts) \[m\];
    /// `height` = largest `s` + Δx/2 \[m\]. Each particle stands for a cell of side Δx, so
    /// Δx/2 is the fluid's extent beyond the outermost centre. Zero when no fluid qualifies.
    Spread {
        /// The plane's normal axis (2 = z in 3D, 1 = y in 2D).
        axis: usize,
        /// The plane's position on `axis` \[m\]: the wall's surface, or a film's.
        position: f64,
        /// Thickness of the contact layer \[m\] (absent: 1.5 Δx, the first row of particles:
        /// a dummy wall holds it about one spacing off the plane, measured on
        /// `droplet_impact`).
        #[serde(default)]
        layer: Option<f64>,
    },
    /// The pressure on a 2D drop's outline against Young–Laplace (Zhou 2021 §3.4): each
    /// outline point (the scheme's own outline, OTM's boundary nodes; else the farthest
    /// particle from the centroid in sectors about 2 Δx wide) against `γ κ`, κ from the
    /// least-squares circle through it and its two neighbours on each side: `error_rms` of
    /// `p − γ κ` and `error_max`, the largest `|p − γ κ|`, `laplace_mean` (mean `γ κ`),
    /// `p_mean` \[Pa\] and `count` over the points compared.
    YoungLaplace {
        /// Outline points below this height on y \[m\] shape the circle fits but are not
        /// compared (the contact with a plate; all are compared when absent).
        #[serde(default)]
        above: Option<f64>,
    },
}

/// A slab `range[0] <= x[axis] <= range[1]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Slab {
    /// Axis normal to the slab.
    pub axis: usize,
    /// Extent on that axis \[m\].
    pub range: [f64; 2],
}

/// Output cadence.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Record probes every this many steps (and at t = 0 and the last step).
    #[serde(default = "default_probe_every")]
    pub probe_every: usize,
    /// Write a VTK frame every this many steps (0 = none; `meniscus run --vtk` sets it).
    #[serde(default)]
    pub vtk_every: usize,
    /// Times \[s\] at which probes are also recorded; steps are shortened to land on them
    /// exactly (increasing, within the end time).
    #[serde(default)]
    pub probe_times: Vec<f64>,
    /// Times \[s\] at which every particle's position, velocity and pressure is recorded
    /// ([`crate::RunReport::snapshots`]; `meniscus run` writes `DIR/snapshots/`); steps are
    /// shortened to land on them exactly (increasing, from 0 to the end time, at most 100).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub snapshot_times: Vec<f64>,
}

impl Default for OutputSpec {
    fn default() -> Self {
        Self {
            probe_every: default_probe_every(),
            vtk_every: 0,
            probe_times: Vec::new(),
            snapshot_times: Vec::new(),
        }
    }
}

fn default_probe_every() -> usize {
    10
}

/// Output keys of a scene's probes, in order: the kind's name, with `_1`, `_2`, ... for
/// repeated kinds (`velocity_profile`, `velocity_profile_1`).
pub fn probe_keys(probes: &[Probe]) -> Vec<String> {
    let mut seen: std::collections::BTreeMap<&'static str, usize> = Default::default();
    probes
        .iter()
        .map(|p| {
            let base = p.kind_name();
            let k = seen.entry(base).or_insert(0);
            let key = if *k == 0 { base.to_string() } else { format!("{base}_{k}") };
            *k += 1;
            key
        })
        .collect()
}

impl Probe {
    /// Output key of the probe's kind (`probes.json`).
    pub fn kind_name(&self) -> &'static str {
        match self {
            Probe::EllipseAxes {} => "ellipse_axes",
            Probe::PressureAt { .. } => "pressure_at",
            Probe::MeanPressure { .. } => "mean_pressure",
            Probe::PressureGradient { .. } => "pressure_gradient",
            Probe::EllipsoidAxes {} => "ellipsoid_axes",
            Probe::KineticEnergy {} => "kinetic_energy",
            Probe::Momentum {} => "momentum",
            Probe::Disorder {} => "disorder",
            Probe::Solver {} => "solver",
            Probe::VelocityProfile { .. } => "velocity_profile",
            Probe::RadialProfile { .. } => "radial_profile",
            Probe::MassBalance {} => "mass_balance",
            Probe::MaxSpeed {} => "max_speed",
            Probe::DropShape {} => "drop_shape",
            Probe::Spread { .. } => "spread",
            Probe::YoungLaplace { .. } => "young_laplace",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{IsphOptions, ViscousOperator};

    /// An absent free-surface threshold is `D − ½`; a given one is kept.
    #[test]
    fn the_free_surface_threshold_defaults_to_d_minus_a_half() {
        let o: IsphOptions = serde_json::from_value(
            serde_json::json!({"ppe": {"solver": "cg", "tolerance": 1e-3, "max_iterations": 100}}),
        )
        .expect("options without a threshold");
        assert_eq!((o.free_surface_threshold(2), o.free_surface_threshold(3)), (1.5, 2.5));
        let o = IsphOptions { free_surface_threshold: Some(2.25), ..o };
        assert!((o.free_surface_threshold(3) - 2.25).abs() < 1e-15);
    }

    /// Error messages name an operator as the scene file spells it.
    #[test]
    fn viscous_operator_scene_names_are_the_serde_names() {
        for op in [ViscousOperator::ShaoLo, ViscousOperator::MonaghanCleary, ViscousOperator::Consistent] {
            let json = serde_json::to_string(&op).expect("serialises");
            assert_eq!(json, format!("\"{}\"", op.scene_name()));
        }
    }
}
