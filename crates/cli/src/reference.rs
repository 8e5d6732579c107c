//! `meniscus reference`: print analytical reference data from `meniscus-reference`.
//!
//! Every subcommand prints an aligned table, or with `--json` a JSON array (or object) on one
//! line. Bad arguments (non-positive or non-finite parameters, negative or missing times,
//! points outside the domain) are reported as [`crate::UsageError`] (exit code 2), naming
//! the argument.

use crate::UsageError;
use clap::Subcommand;
use meniscus_reference::capillarity::{self, Dimension};
use meniscus_reference::elliptical_drop::EllipticalDrop;
use meniscus_reference::pipe::HagenPoiseuille;
use meniscus_reference::poiseuille::PlanePoiseuille;
use meniscus_reference::rotating_square::RotatingSquare;
use meniscus_reference::{ReferenceError, entrance_length};
use serde::Serialize;

/// Reference solutions that can be printed.
#[derive(Subcommand, Debug)]
pub enum ReferenceCommand {
    /// Inviscid elliptical drop (Monaghan 1994; Colagrossi 2005; REFERENCES.md §1):
    /// x semi-axis a, y semi-axis b = R^2/a, strain rate A (u = -A x, v = +A y) and centre
    /// pressure pc at the given times.
    EllipticalDrop {
        /// Initial radius R [m].
        #[arg(long, allow_negative_numbers = true)]
        radius: f64,
        /// Initial strain rate A0 [1/s] (initial velocity u = -A0 x, v = +A0 y).
        #[arg(long, allow_negative_numbers = true)]
        a0: f64,
        /// Density rho [kg/m^3].
        #[arg(long, allow_negative_numbers = true)]
        density: f64,
        /// Times t [s], comma-separated, each >= 0.
        #[arg(long, required = true, value_delimiter = ',', allow_negative_numbers = true)]
        times: Vec<f64>,
        /// Print JSON: [{"t", "a", "b", "strain_rate", "pc"}, ...].
        #[arg(long)]
        json: bool,
    },
    /// Start-up of plane Poiseuille flow between plates at y = 0 and y = width, driven from
    /// rest by a body force (Morris et al. 1997, corrected sign; REFERENCES.md §3a).
    /// Accurate to 1e-8 u_max.
    PoiseuilleStartup {
        /// Channel width D [m].
        #[arg(long, allow_negative_numbers = true)]
        width: f64,
        /// KINEMATIC viscosity nu [m^2/s] (not the dynamic viscosity mu = rho nu).
        #[arg(long, allow_negative_numbers = true)]
        viscosity: f64,
        /// Body force per unit mass F [m/s^2] along x (positive F gives positive flow).
        #[arg(long, allow_negative_numbers = true)]
        force: f64,
        /// Wall-normal positions y [m], comma-separated, each in [0, width].
        #[arg(long, required = true, value_delimiter = ',', allow_negative_numbers = true)]
        y: Vec<f64>,
        /// Times t [s], comma-separated, each >= 0.
        #[arg(long, required = true, value_delimiter = ',', allow_negative_numbers = true)]
        times: Vec<f64>,
        /// Print JSON: [{"t", "y", "u"}, ...] (all y for the first time, then the next time).
        #[arg(long)]
        json: bool,
    },
    /// Start-up of Hagen–Poiseuille pipe flow from rest (REFERENCES.md §3d). Accurate to
    /// 1e-8 u_max.
    PipeStartup {
        /// Pipe radius R [m].
        #[arg(long, allow_negative_numbers = true)]
        radius: f64,
        /// KINEMATIC viscosity nu [m^2/s].
        #[arg(long, allow_negative_numbers = true)]
        viscosity: f64,
        /// Driving gradient G = -(dp/dx)/rho [m/s^2] (or a body force per unit mass).
        #[arg(long, allow_negative_numbers = true)]
        gradient: f64,
        /// Radial positions r [m], comma-separated, each in [0, radius].
        #[arg(long, required = true, value_delimiter = ',', allow_negative_numbers = true)]
        r: Vec<f64>,
        /// Times t [s], comma-separated, each >= 0.
        #[arg(long, required = true, value_delimiter = ',', allow_negative_numbers = true)]
        times: Vec<f64>,
        /// Print JSON: [{"t", "r", "u"}, ...].
        #[arg(long)]
        json: bool,
    },
    /// Initial pressure of the inviscid rotating square patch (Colagrossi 2005;
    /// REFERENCES.md §2) at points (x_i, y_i) measured from the centre.
    RotatingSquare {
        /// Side L [m].
        #[arg(long, allow_negative_numbers = true)]
        side: f64,
        /// Angular velocity omega [rad/s] (u = omega y, v = -omega x).
        #[arg(long, allow_negative_numbers = true)]
        omega: f64,
        /// Density rho [kg/m^3].
        #[arg(long, allow_negative_numbers = true)]
        density: f64,
        /// x coordinates [m], comma-separated, each in [-L/2, L/2] (default: the centre).
        #[arg(long, value_delimiter = ',', allow_negative_numbers = true, default_value = "0")]
        x: Vec<f64>,
        /// y coordinates [m], comma-separated, as many as x (default: the centre).
        #[arg(long, value_delimiter = ',', allow_negative_numbers = true, default_value = "0")]
        y: Vec<f64>,
        /// Print JSON: [{"x", "y", "p"}, ...].
        #[arg(long)]
        json: bool,
    },
    /// Capillarity of a drop (REFERENCES.md §4): Laplace pressure, oscillation frequency,
    /// period and viscous damping rate of the given modes.
    Capillary {
        /// Space dimension: 2 (cylindrical drop) or 3 (spherical drop).
        #[arg(long, value_parser = clap::value_parser!(u8).range(2..=3))]
        dim: u8,
        /// Drop radius R [m].
        #[arg(long, allow_negative_numbers = true)]
        radius: f64,
        /// Surface tension sigma [N/m].
        #[arg(long, allow_negative_numbers = true)]
        sigma: f64,
        /// Density of the drop rho [kg/m^3].
        #[arg(long, allow_negative_numbers = true)]
        density: f64,
        /// KINEMATIC viscosity nu [m^2/s] for the damping rate (omit for an inviscid drop).
        #[arg(long, allow_negative_numbers = true)]
        viscosity: Option<f64>,
        /// Mode numbers n >= 2, comma-separated.
        #[arg(long, value_delimiter = ',', default_value = "2")]
        modes: Vec<usize>,
        /// Print JSON: {"laplace_pressure", "modes": [{"n", "omega", "period", "damping_rate"}]}.
        #[arg(long)]
        json: bool,
    },
    /// Laminar development length from a uniform inlet (Durst et al. 2005; Chen 1973;
    /// REFERENCES.md §3c): channel L_e/H with Re = U H/nu, pipe L_e/D with Re = U D/nu.
    EntranceLength {
        /// Reynolds numbers, comma-separated, each >= 0.
        #[arg(long, required = true, value_delimiter = ',', allow_negative_numbers = true)]
        reynolds: Vec<f64>,
        /// Print JSON: [{"reynolds", "channel_durst", "channel_chen", "pipe_durst", "pipe_classical"}].
        #[arg(long)]
        json: bool,
    },
}

/// Runs one `meniscus reference` subcommand, printing to stdout.
pub fn run(cmd: &ReferenceCommand) -> anyhow::Result<()> {
    match cmd {
        ReferenceCommand::EllipticalDrop { radius, a0, density, times, json } => {
            positive("--radius", *radius)?;
            positive("--a0", *a0)?;
            positive("--density", *density)?;
            check_times(times)?;
            let drop = EllipticalDrop::new(*radius, *a0, *density).map_err(library)?;
            let states = drop.states_at(times).map_err(library)?;
            if *json {
                return print_json(&states);
            }
            let rows = states
                .iter()
                .map(|s| {
                    vec![
                        format!("{}", s.t),
                        format!("{:.12}", s.a),
                        format!("{:.12}", s.b),
                        format!("{:.10}", s.strain_rate),
                        format!("{:.9e}", s.pc),
                    ]
                })
                .collect();
            print_table(&["t [s]", "a [m]", "b [m]", "A [1/s]", "pc [Pa]"], rows);
        }
        ReferenceCommand::PoiseuilleStartup { width, viscosity, force, y, times, json } => {
            positive("--width", *width)?;
            positive("--viscosity", *viscosity)?;
            finite("--force", *force)?;
            check_positions("--y", y, 0.0, *width, "[0, width]")?;
            check_times(times)?;
            let channel = PlanePoiseuille::new(*width, *force, *viscosity).map_err(library)?;
            let mut points = Vec::with_capacity(times.len() * y.len());
            for &t in times {
                for &yi in y {
                    points.push(ProfilePoint { t, y: yi, u: channel.velocity(yi, t).map_err(library)? });
                }
            }
            if *json {
                return print_json(&points);
            }
            println!(
                "# u_max = F D^2/(8 nu) = {:.9e} m/s, D^2/nu = {} s",
                channel.u_max(),
                channel.viscous_time()
            );
            print_profile(&points, "y [m]", channel.u_max());
        }
        ReferenceCommand::PipeStartup { radius, viscosity, gradient, r, times, json } => {
            positive("--radius", *radius)?;
            positive("--viscosity", *viscosity)?;
            finite("--gradient", *gradient)?;
            check_positions("--r", r, 0.0, *radius, "[0, radius]")?;
            check_times(times)?;
            let pipe = HagenPoiseuille::new(*radius, *gradient, *viscosity).map_err(library)?;
            let mut points = Vec::with_capacity(times.len() * r.len());
            for &t in times {
                for &ri in r {
                    points.push(RadialPoint { t, r: ri, u: pipe.velocity(ri, t).map_err(library)? });
                }
            }
            if *json {
                return print_json(&points);
            }
            println!("# u_max = G R^2/(4 nu) = {:.9e} m/s, R^2/nu = {} s", pipe.u_max(), pipe.viscous_time());
            let as_profile: Vec<ProfilePoint> =
                points.iter().map(|p| ProfilePoint { t: p.t, y: p.r, u: p.u }).collect();
            print_profile(&as_profile, "r [m]", pipe.u_max());
        }
        ReferenceCommand::RotatingSquare { side, omega, density, x, y, json } => {
            positive("--side", *side)?;
            finite("--omega", *omega)?;
            positive("--density", *density)?;
            if x.len() != y.len() {
                return Err(usage(format!(
                    "--x and --y must list the same number of coordinates (got {} and {})",
                    x.len(),
                    y.len()
                )));
            }
            let half = 0.5 * side;
            check_positions("--x", x, -half, half, "[-side/2, side/2]")?;
            check_positions("--y", y, -half, half, "[-side/2, side/2]")?;
            let patch = RotatingSquare::new(*side, *omega, *density).map_err(library)?;
            let points = x
                .iter()
                .zip(y)
                .map(|(&x, &y)| Ok(PressurePoint { x, y, p: patch.pressure(x, y).map_err(library)? }))
                .collect::<anyhow::Result<Vec<_>>>()?;
            if *json {
                return print_json(&points);
            }
            let scale = density * omega * omega * side * side;
            let rows = points
                .iter()
                .map(|p| {
                    let ratio = if scale > 0.0 { fixed(p.p / scale, 10) } else { "-".into() };
                    vec![format!("{}", p.x), format!("{}", p.y), format!("{:.10e}", p.p), ratio]
                })
                .collect();
            print_table(&["x [m]", "y [m]", "p [Pa]", "p/(rho omega^2 L^2)"], rows);
        }
        ReferenceCommand::Capillary { dim, radius, sigma, density, viscosity, modes, json } => {
            positive("--radius", *radius)?;
            positive("--sigma", *sigma)?;
            positive("--density", *density)?;
            if let Some(nu) = viscosity {
                positive("--viscosity", *nu)?;
            }
            if modes.is_empty() {
                return Err(usage("--modes must list at least one mode".into()));
            }
            if let Some(n) = modes.iter().find(|&&n| n < 2) {
                return Err(usage(format!("--modes: every mode must be at least 2 (got {n})")));
            }
            let dimension = if *dim == 2 { Dimension::Two } else { Dimension::Three };
            let laplace_pressure =
                capillarity::laplace_pressure(dimension, *sigma, *radius).map_err(library)?;
            let mut rows = Vec::with_capacity(modes.len());
            for &n in modes {
                let omega =
                    capillarity::oscillation_angular_frequency(dimension, n, *sigma, *density, *radius)
                        .map_err(library)?;
                let damping_rate = match viscosity {
                    Some(nu) => Some(capillarity::damping_rate(dimension, n, *nu, *radius).map_err(library)?),
                    None => None,
                };
                rows.push(CapillaryMode {
                    n,
                    omega,
                    period: 2.0 * std::f64::consts::PI / omega,
                    damping_rate,
                });
            }
            if *json {
                return print_json(&CapillaryReport { laplace_pressure, modes: rows });
            }
            println!("# Laplace pressure jump = {laplace_pressure:.9e} Pa ({dim}D)");
            let table = rows
                .iter()
                .map(|m| {
                    vec![
                        m.n.to_string(),
                        format!("{:.9e}", m.omega),
                        format!("{:.9e}", m.period),
                        m.damping_rate.map_or_else(|| "-".into(), |b| format!("{b:.9e}")),
                    ]
                })
                .collect();
            print_table(&["n", "omega [rad/s]", "period [s]", "damping [1/s]"], table);
        }
        ReferenceCommand::EntranceLength { reynolds, json } => {
            if reynolds.is_empty() {
                return Err(usage("--reynolds must list at least one value".into()));
            }
            for &re in reynolds {
                if !(re.is_finite() && re >= 0.0) {
                    return Err(usage(format!("--reynolds: every value must be finite and >= 0 (got {re})")));
                }
            }
            let rows = reynolds
                .iter()
                .map(|&re| {
                    Ok(EntranceRow {
                        reynolds: re,
                        channel_durst: entrance_length::channel_durst(re).map_err(library)?,
                        channel_chen: entrance_length::channel_chen(re).map_err(library)?,
                        pipe_durst: entrance_length::pipe_durst(re).map_err(library)?,
                        pipe_classical: entrance_length::pipe_classical(re).map_err(library)?,
                    })
                })
                .collect::<anyhow::Result<Vec<_>>>()?;
            if *json {
                return print_json(&rows);
            }
            let table = rows
                .iter()
                .map(|r| {
                    vec![
                        format!("{}", r.reynolds),
                        format!("{:.4}", r.channel_durst),
                        format!("{:.4}", r.channel_chen),
                        format!("{:.4}", r.pipe_durst),
                        format!("{:.4}", r.pipe_classical),
                    ]
                })
                .collect();
            print_table(
                &["Re", "channel L/H Durst", "channel L/H Chen", "pipe L/D Durst", "pipe L/D 0.06 Re"],
                table,
            );
        }
    }
    Ok(())
}

#[derive(Serialize)]
struct ProfilePoint {
    t: f64,
    y: f64,
    u: f64,
}

#[derive(Serialize)]
struct RadialPoint {
    t: f64,
    r: f64,
    u: f64,
}

#[derive(Serialize)]
struct PressurePoint {
    x: f64,
    y: f64,
    p: f64,
}

#[derive(Serialize)]
struct CapillaryMode {
    n: usize,
    omega: f64,
    period: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    damping_rate: Option<f64>,
}

#[derive(Serialize)]
struct CapillaryReport {
    laplace_pressure: f64,
    modes: Vec<CapillaryMode>,
}

#[derive(Serialize)]
struct EntranceRow {
    reynolds: f64,
    channel_durst: f64,
    channel_chen: f64,
    pipe_durst: f64,
    pipe_classical: f64,
}

fn usage(message: String) -> anyhow::Error {
    anyhow::Error::new(UsageError(message))
}

/// Parameter errors from the library are usage errors; integration failures are not.
fn library(e: ReferenceError) -> anyhow::Error {
    match e {
        ReferenceError::Integration { .. } => anyhow::Error::new(e),
        _ => usage(format!("invalid argument: {e}")),
    }
}

fn positive(arg: &str, value: f64) -> anyhow::Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(usage(format!("{arg} must be positive and finite (got {value})")))
    }
}

fn finite(arg: &str, value: f64) -> anyhow::Result<f64> {
    if value.is_finite() { Ok(value) } else { Err(usage(format!("{arg} must be finite (got {value})"))) }
}

fn check_times(times: &[f64]) -> anyhow::Result<()> {
    if times.is_empty() {
        return Err(usage("--times must list at least one time".into()));
    }
    match times.iter().find(|t| !(t.is_finite() && **t >= 0.0)) {
        Some(t) => Err(usage(format!("--times: every time must be finite and >= 0 (got {t})"))),
        None => Ok(()),
    }
}

fn check_positions(arg: &str, values: &[f64], lo: f64, hi: f64, interval: &str) -> anyhow::Result<()> {
    if values.is_empty() {
        return Err(usage(format!("{arg} must list at least one position")));
    }
    match values.iter().find(|v| !(v.is_finite() && (lo..=hi).contains(*v))) {
        Some(v) => Err(usage(format!("{arg}: every value must lie in {interval} = [{lo}, {hi}] (got {v})"))),
        None => Ok(()),
    }
}

fn print_json<T: Serialize + ?Sized>(value: &T) -> anyhow::Result<()> {
    println!("{}", serde_json::to_string(value)?);
    Ok(())
}

fn print_profile(points: &[ProfilePoint], position: &str, u_max: f64) {
    let rows = points
        .iter()
        .map(|p| {
            let ratio = if u_max.abs() > 0.0 { fixed(p.u / u_max, 10) } else { "-".into() };
            vec![format!("{}", p.t), format!("{}", p.y), format!("{:.9e}", p.u), ratio]
        })
        .collect();
    print_table(&["t [s]", position, "u [m/s]", "u/u_max"], rows);
}

/// `value` with `decimals` decimals, without the sign of a value that rounds to zero.
fn fixed(value: f64, decimals: usize) -> String {
    let s = format!("{value:.decimals$}");
    match s.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => s,
    }
}

/// Prints right-aligned columns separated by two spaces.
fn print_table(header: &[&str], rows: Vec<Vec<String>>) {
    let mut widths: Vec<usize> = header.iter().map(|h| h.chars().count()).collect();
    for row in &rows {
        for (w, cell) in widths.iter_mut().zip(row) {
            *w = (*w).max(cell.chars().count());
        }
    }
    let line = |cells: Vec<&str>| {
        cells.iter().zip(&widths).map(|(c, w)| format!("{c:>w$}")).collect::<Vec<_>>().join("  ")
    };
    println!("{}", line(header.to_vec()));
    for row in &rows {
        println!("{}", line(row.iter().map(String::as_str).collect()));
    }
}
