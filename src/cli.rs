//! The `blmesh` command line: `info`, `check`, `mesh` and `yplus`.
//!
//! Errors are printed as one message naming the problem and exit with a non-zero code; outputs
//! are written atomically, so a failed run leaves no partial file.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Result;
use clap::{Args, Parser, Subcommand};

use crate::api::{self, Settings};
use crate::config::Config;
use crate::progress::Progress;
use crate::surface::info::ValidationSummary;
use crate::yplus::FlowConditions;

/// Exit code for invalid input or a failed run (clap itself uses 2 for bad usage).
const EXIT_FAILURE: u8 = 1;

#[derive(Parser, Debug)]
#[command(name = "blmesh", version, about = "Boundary-layer volume meshes for CFD")]
struct Cli {
    /// Print no progress and no summary (errors are still printed).
    #[arg(short, long, global = true)]
    quiet: bool,
    /// More log output (-v info, -vv debug).
    #[arg(short, long, global = true, action = clap::ArgAction::Count)]
    verbose: u8,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Read and validate a surface; print its topology, patches and features.
    Info {
        surface: PathBuf,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
        /// Edges turning more than this (degrees) are ridges.
        #[arg(long, default_value_t = crate::config::DEFAULT_FEATURE_ANGLE)]
        feature_angle: f64,
    },
    /// Check a volume mesh (.msh, .vtu): positive volumes, conformity, volume identity, quality,
    /// finite-volume measures. Exits with 0 only when the mesh is valid and a finite-volume solver
    /// would accept it (no wrong face pyramid, no face at 90 degrees non-orthogonality or more).
    Check {
        mesh: PathBuf,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Build the boundary-layer mesh of a surface.
    Mesh(MeshArgs),
    /// First-layer height for a target y+ (Schlichting flat-plate skin friction, Re < 1e9).
    Yplus(YplusArgs),
}

#[derive(Args, Debug)]
struct YplusArgs {
    /// Reynolds number on the reference length.
    #[arg(long, allow_negative_numbers = true)]
    re: f64,
    /// Reference length (the height comes out in its units).
    #[arg(long, allow_negative_numbers = true)]
    length: f64,
    /// Target y+ of the first layer.
    #[arg(long, allow_negative_numbers = true)]
    yplus: f64,
    /// Free-stream velocity (with --density and --viscosity; SI units, --length in m).
    #[arg(long, allow_negative_numbers = true, requires_all = ["density", "viscosity"])]
    velocity: Option<f64>,
    /// Density.
    #[arg(long, allow_negative_numbers = true, requires_all = ["velocity", "viscosity"])]
    density: Option<f64>,
    /// Dynamic viscosity.
    #[arg(long, allow_negative_numbers = true, requires_all = ["velocity", "density"])]
    viscosity: Option<f64>,
}

#[derive(Args, Debug)]
struct MeshArgs {
    /// Input surface (.stl, .obj, .off, .msh, .mesh, .meshb, .tri, .uh3d).
    input: PathBuf,
    /// Output mesh; the format follows the extension (.msh, .vtu, .su2, .mesh, .meshb, .cgns,
    /// .ugrid / .b8.ugrid / .lb8.ugrid with a FUN3D .mapbc beside), or an OpenFOAM polyMesh
    /// directory when the last component is `polyMesh`.
    #[arg(short, long)]
    output: PathBuf,
    /// TOML configuration file (flags override it).
    #[arg(long)]
    config: Option<PathBuf>,
    #[command(flatten)]
    settings: Settings,
    /// Write MSH as ASCII instead of binary.
    #[arg(long)]
    ascii: bool,
    /// Also write the run's report as JSON.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Also write pictures (PNG) of cuts through the mesh, a quality histogram and histograms of
    /// the faces' non-orthogonality by cell kind into DIR.
    #[arg(long, value_name = "DIR")]
    pictures: Option<PathBuf>,
}

/// Run the command line; returns the process exit code.
pub fn main() -> ExitCode {
    // Before any thread starts (see the module).
    crate::interrupt::install();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() { 2 } else { 0 });
        }
    };
    init_logging(cli.verbose);
    let progress = Progress::new(cli.quiet);
    let result = match cli.command {
        Command::Info { surface, json, feature_angle } => info(&surface, json, feature_angle),
        Command::Check { mesh, json } => check(&mesh, json),
        Command::Mesh(args) => mesh(&args, cli.quiet, progress),
        Command::Yplus(args) => yplus(&args),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {}", api::error_message(&e));
            ExitCode::from(EXIT_FAILURE)
        }
    }
}

fn init_logging(verbose: u8) {
    let level = match verbose {
        0 => "warn",
        1 => "info",
        _ => "debug",
    };
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(level));
    let _ = tracing_subscriber::fmt().with_env_filter(filter).with_writer(std::io::stderr).try_init();
}

fn info(path: &Path, json: bool, feature_angle: f64) -> Result<ExitCode> {
    let info = api::surface_info(path, feature_angle)?;
    if json {
        print_out(&serde_json::to_string_pretty(&info)?);
    } else {
        print_out(&format!("{}\n{info}", path.display()));
    }
    if let ValidationSummary::Invalid { error } = &info.validation {
        eprintln!("error: {}: invalid surface: {error}", path.display());
        return Ok(ExitCode::from(EXIT_FAILURE));
    }
    Ok(ExitCode::SUCCESS)
}

fn check(path: &Path, json: bool) -> Result<ExitCode> {
    let report = api::check_file(path)?;
    if json {
        print_out(&serde_json::to_string_pretty(&report)?);
    } else {
        print_out(&format!("{}\n{report}", path.display()));
    }
    Ok(if api::accepted(&report) { ExitCode::SUCCESS } else { ExitCode::from(EXIT_FAILURE) })
}

fn mesh(args: &MeshArgs, quiet: bool, progress: Progress) -> Result<ExitCode> {
    let format = api::output_format(&args.output, args.ascii)?;
    check_outputs_writable(args, format)?;
    let config = match &args.config {
        Some(path) => Config::from_toml_file(path)?,
        None => Config::default(),
    };
    let config = args.settings.apply(config)?;
    let out = api::mesh_file(&args.input, &config, args.settings.no_core, progress)?;
    api::write_mesh(&args.output, &out.mesh, format, &config)?;
    if let Some(report_path) = &args.report {
        api::write_report(report_path, &out)?;
    }
    if let Some(dir) = &args.pictures {
        api::write_pictures(dir, &out)?;
    }
    if !quiet {
        print_out(&out.report.to_string());
    }
    Ok(ExitCode::SUCCESS)
}

/// Every output can be written: fail before the meshing, not after it.
fn check_outputs_writable(args: &MeshArgs, format: crate::io::MeshFormat) -> Result<()> {
    let pictures = args.pictures.as_ref().map(|dir| (dir.join("overview.png"), true));
    let outputs = [
        Some((args.output.clone(), format == crate::io::MeshFormat::Foam)),
        args.report.clone().map(|r| (r, false)),
        pictures,
    ];
    for (path, created_dirs) in outputs.into_iter().flatten() {
        crate::io::check_writable(&path, created_dirs)
            .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?;
    }
    Ok(())
}

fn yplus(args: &YplusArgs) -> Result<ExitCode> {
    let flow = FlowConditions {
        reynolds: args.re,
        length: args.length,
        velocity: args.velocity,
        density: args.density,
        viscosity: args.viscosity,
    };
    let h = flow.first_height(args.yplus)?;
    let dimensional = flow.velocity.is_some();
    // Dimensional inputs are one unit system: SI units are shown.
    let length_unit = if dimensional { "m" } else { "(any length unit)" };
    let mut lines = vec![
        "flat-plate skin friction (Schlichting): Cf = (2 log10(Re) - 0.65)^-2.3, valid for Re < 1e9".into(),
        format!("Reynolds number    Re    = {:.6e}", flow.reynolds),
        format!("reference length   L     = {:.6e} {length_unit}", flow.length),
        format!("target y+                = {}", args.yplus),
    ];
    if let (Some(u), Some(rho), Some(mu)) = (flow.velocity, flow.density, flow.viscosity) {
        lines.push(format!("velocity           U     = {u:.6e} m/s"));
        lines.push(format!("density            rho   = {rho:.6e} kg/m^3"));
        lines.push(format!("dynamic viscosity  mu    = {mu:.6e} Pa s"));
    }
    lines.push(format!("skin friction      Cf    = {:.6e}", h.cf));
    if let (Some(tau), Some(u_tau)) = (h.wall_shear_stress, h.friction_velocity) {
        lines.push(format!("wall shear stress  tau_w = {tau:.6e} Pa"));
        lines.push(format!("friction velocity  u_tau = {u_tau:.6e} m/s"));
    }
    let unit = if dimensional { "m" } else { "(units of L)" };
    lines.push(format!("first layer height y     = {:.6e} {unit}", h.height));
    print_out(&lines.join("\n"));
    Ok(ExitCode::SUCCESS)
}

/// Print to stdout; a closed pipe (`blmesh info x | head`) is not an error worth a panic.
fn print_out(text: &str) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    let _ = writeln!(out, "{text}").and_then(|()| out.flush());
}
