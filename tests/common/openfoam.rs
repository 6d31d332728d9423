//! Running OpenFOAM's own tools on a case we wrote, and reading `checkMesh`'s figures, so tests can
//! hold our polyMesh (and later our own finite-volume measures) against OpenFOAM's verdict.
//!
//! Debian's `openfoam` package puts the tools on PATH; they find their `etc/` through
//! `WM_PROJECT_DIR`, set here, so its `etc/bashrc` need not be sourced.

use std::path::Path;
use std::process::Command;
use std::time::Instant;

/// Where Debian's package keeps OpenFOAM's `etc/`.
const DEBIAN_PROJECT_DIR: &str = "/usr/share/openfoam";

/// Whether OpenFOAM's tools can run here; if not, says why on stderr (the test then skips).
pub fn available() -> bool {
    let ok = Command::new("checkMesh").arg("-help").env("WM_PROJECT_DIR", project_dir()).output();
    let ok = ok.is_ok_and(|o| o.status.success());
    if !ok {
        eprintln!(
            "SKIPPED: OpenFOAM's checkMesh is not installed (scripts/setup.sh installs Debian's openfoam)"
        );
    }
    ok
}

fn project_dir() -> String {
    std::env::var("WM_PROJECT_DIR").unwrap_or_else(|_| DEBIAN_PROJECT_DIR.to_owned())
}

/// An OpenFOAM tool run on `case`: its log (stdout and stderr), exit status and wall time.
pub struct Run {
    pub log: String,
    pub success: bool,
    pub seconds: f64,
}

pub fn run(tool: &str, case: &Path) -> Run {
    let start = Instant::now();
    let out = Command::new(tool)
        .arg("-case")
        .arg(case)
        .env("WM_PROJECT_DIR", project_dir())
        .output()
        .unwrap_or_else(|e| panic!("{tool} runs: {e}"));
    let log = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    Run { log, success: out.status.success(), seconds: start.elapsed().as_secs_f64() }
}

fn foam_file(class: &str, object: &str, body: &str) -> String {
    format!(
        "FoamFile\n{{\n    version 2.0;\n    format ascii;\n    class {class};\n    object {object};\n}}\n{body}"
    )
}

fn write(case: &Path, relative: &str, text: &str) {
    let path = case.join(relative);
    std::fs::create_dir_all(path.parent().expect("a parent")).expect("the case directory");
    std::fs::write(&path, text).expect("a case file");
}

/// The `system/` files every tool needs: `controlDict`, and `fvSchemes` and `fvSolution` for
/// `potentialFoam` (a steady Laplace solve for the velocity potential `Phi`).
pub fn write_system(case: &Path) {
    let control = "application potentialFoam;\nstartFrom startTime;\nstartTime 0;\nstopAt endTime;\n\
                   endTime 1;\ndeltaT 1;\nwriteControl timeStep;\nwriteInterval 1;\n";
    write(case, "system/controlDict", &foam_file("dictionary", "controlDict", control));
    let schemes = "ddtSchemes { default steadyState; }\ngradSchemes { default Gauss linear; }\n\
                   divSchemes { default none; div(phi,U) bounded Gauss linear; }\n\
                   laplacianSchemes { default Gauss linear corrected; }\n\
                   interpolationSchemes { default linear; }\nsnGradSchemes { default corrected; }\n";
    write(case, "system/fvSchemes", &foam_file("dictionary", "fvSchemes", schemes));
    let solution = "solvers\n{\n    Phi { solver GAMG; smoother DIC; tolerance 1e-06; relTol 0.01; }\n}\n\
                    potentialFlow { nNonOrthogonalCorrectors 3; PhiRefCell 0; PhiRefValue 0; }\n";
    write(case, "system/fvSolution", &foam_file("dictionary", "fvSolution", solution));
}

/// `0/U` and `0/p` for a body in a uniform stream along x: the stream on every `patch`, no flow
/// through walls and symmetry patches. `patches` are (name, type) as in the `boundary` file.
pub fn write_stream_fields(case: &Path, patches: &[(String, String)]) {
    let entry = |(name, kind): &(String, String), inflow: &str| {
        let bc = match kind.as_str() {
            "patch" => format!("type fixedValue; value uniform {inflow};"),
            "wall" => "type slip;".to_owned(),
            other => format!("type {other};"),
        };
        format!("    {name} {{ {bc} }}\n")
    };
    let u: String = patches.iter().map(|p| entry(p, "(1 0 0)")).collect();
    let p: String =
        patches.iter().map(|(name, kind)| entry(&(name.clone(), pressure_type(kind)), "0")).collect();
    let body = |internal: &str, bcs: &str| {
        format!(
            "dimensions [0 1 -1 0 0 0 0];\ninternalField uniform {internal};\nboundaryField\n{{\n{bcs}}}\n"
        )
    };
    write(case, "0/U", &foam_file("volVectorField", "U", &body("(1 0 0)", &u)));
    let p_body = body("0", &p).replace("[0 1 -1 0 0 0 0]", "[0 2 -2 0 0 0 0]");
    write(case, "0/p", &foam_file("volScalarField", "p", &p_body));
}

/// The pressure condition beside a velocity one: zero gradient wherever the velocity is set.
fn pressure_type(kind: &str) -> String {
    match kind {
        "patch" | "wall" => "zeroGradient".to_owned(),
        other => other.to_owned(),
    }
}

/// The (name, type) of every patch in a polyMesh `boundary` file.
pub fn patches(boundary: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut name: Option<&str> = None;
    for line in boundary.lines().map(str::trim) {
        if let Some(kind) = line.strip_prefix("type").map(|t| t.trim().trim_end_matches(';')) {
            out.extend(name.take().map(|n| (n.to_owned(), kind.to_owned())));
        } else if !line.is_empty() && line.chars().all(|c| !"{}();\"/*|\\ ".contains(c)) {
            name = Some(line);
        }
    }
    out
}

/// `checkMesh`'s verdict and figures.
#[derive(Clone, Debug, Default)]
pub struct CheckMesh {
    /// The lines of failed checks (`***`).
    pub failures: Vec<String>,
    pub mesh_ok: bool,
    pub max_non_orthogonality: f64,
    /// Faces above 70 degrees (`*Number of severely non-orthogonal (> 70 degrees) faces`).
    pub severely_non_orthogonal: usize,
    pub max_skewness: f64,
    pub max_aspect_ratio: f64,
    pub cells: usize,
    pub seconds: f64,
}

impl CheckMesh {
    /// Whether the mesh passes by the project's bar: "Mesh OK.", or only high aspect ratio
    /// failed (thin layer cells are meant to be anisotropic).
    pub fn passes(&self) -> bool {
        self.mesh_ok || self.failures.iter().all(|f| f.contains("aspect ratio"))
    }

    pub fn summary(&self) -> String {
        format!(
            "{} cells: max non-orthogonality {:.2} deg, {} faces > 70 deg, max skewness {:.3}, \
             max aspect ratio {:.1}, {} ({:.1} s){}",
            self.cells,
            self.max_non_orthogonality,
            self.severely_non_orthogonal,
            self.max_skewness,
            self.max_aspect_ratio,
            if self.mesh_ok { "Mesh OK" } else { "failed checks" },
            self.seconds,
            self.failures.iter().map(|f| format!("\n  {f}")).collect::<String>()
        )
    }
}

/// Run `checkMesh` on `case` and read its figures.
pub fn check_mesh(case: &Path) -> (CheckMesh, String) {
    let run = run("checkMesh", case);
    assert!(run.log.contains("Checking geometry"), "checkMesh did not get to the geometry:\n{}", run.log);
    let mut check = parse_check_mesh(&run.log);
    check.seconds = run.seconds;
    (check, run.log)
}

/// The figures of a `checkMesh` log.
pub fn parse_check_mesh(log: &str) -> CheckMesh {
    let mut c = CheckMesh { mesh_ok: log.lines().any(|l| l.trim() == "Mesh OK."), ..Default::default() };
    for line in log.lines().map(str::trim) {
        if line.starts_with("***") {
            c.failures.push(line.to_owned());
        }
        if let Some(rest) = line.strip_prefix("cells:") {
            c.cells = first_number(rest).unwrap_or(0.0) as usize;
        } else if let Some(rest) = after(line, "Mesh non-orthogonality Max:") {
            c.max_non_orthogonality = first_number(rest).unwrap_or(f64::NAN);
        } else if let Some(rest) = after(line, "Number of severely non-orthogonal (> 70 degrees) faces:") {
            c.severely_non_orthogonal = first_number(rest).unwrap_or(0.0) as usize;
        } else if let Some(rest) = after(line, "Max skewness =") {
            c.max_skewness = first_number(rest).unwrap_or(f64::NAN);
        } else if let Some(rest) = after(line, "Max aspect ratio") {
            c.max_aspect_ratio = first_number(rest.trim_start_matches([':', '=', ' '])).unwrap_or(f64::NAN);
        }
    }
    c
}

/// The text after `key` anywhere in `line`.
fn after<'a>(line: &'a str, key: &str) -> Option<&'a str> {
    line.find(key).map(|i| &line[i + key.len()..])
}

fn first_number(text: &str) -> Option<f64> {
    text.split(|c: char| c.is_whitespace() || c == ',')
        .find(|t| !t.is_empty())?
        .trim_end_matches('.')
        .parse()
        .ok()
}

/// Our own finite-volume figures (`quality::fv`, from a run's `--report` JSON under
/// `check.fv`) beside checkMesh's: max non-orthogonality within 0.1 degree, the count of faces
/// above 70 degrees within 1% (at least one face). The differences, or why they disagree.
pub fn compare_fv(report_json: &str, check: &CheckMesh) -> Result<String, String> {
    let report: serde_json::Value = serde_json::from_str(report_json).map_err(|e| e.to_string())?;
    let fv = &report["check"]["fv"];
    let max = fv["non_orthogonality_max"].as_f64().ok_or("no check.fv.non_orthogonality_max")?;
    let above = fv["faces_above_70"].as_u64().ok_or("no check.fv.faces_above_70")? as usize;
    let skew = fv["skewness_max"].as_f64().unwrap_or(f64::NAN);
    let text = format!(
        "ours: max non-orthogonality {max:.3} deg, {above} faces > 70, max skewness {skew:.3}; \
         checkMesh: {:.3} deg, {}, {:.3}",
        check.max_non_orthogonality, check.severely_non_orthogonal, check.max_skewness
    );
    let count_tolerance = (check.severely_non_orthogonal as f64 * 0.01).ceil().max(1.0) as usize;
    let agree = (max - check.max_non_orthogonality).abs() <= 0.1
        && above.abs_diff(check.severely_non_orthogonal) <= count_tolerance;
    if agree {
        Ok(text)
    } else {
        Err(text)
    }
}
