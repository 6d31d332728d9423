//! Meshing parameters: the TOML config file, command-line overrides, and their validation.
//!
//! Lengths given by the user are absolute (the surface's own units). Anything not given gets a
//! default relative to the body size (the bounding-box diagonal `D`), so that
//! `blmesh mesh body.stl -o out.msh` gives a sensible mesh for a body of any scale.
//!
//! ```toml
//! flow = "external"            # or "internal"
//! farfield = "box"             # or "sphere"; ignored for internal flow
//! feature_angle = 30.0         # degrees: edges turning more are ridges
//! fan_angle = 20.0             # degrees: largest angle between neighbouring fan normals
//! [layers]
//! first_height = 1.0e-5        # h0, or: yplus = 1.0 with [flow_conditions] (see `crate::yplus`)
//! growth = 1.2                 # r: layer k is h0 r^k high
//! count = 25                   # or: thickness = 0.05, or: count = "auto" (stop at isotropy)
//! first_aspect = 2.0           # where stacks stop: first layer at most 1/2 of the wall's edges (0: off)
//! [[patch]]
//! match = "face9"              # patch name or regex (whole name)
//! role = "symmetry"            # wall | symmetry | farfield | inlet | outlet | none
//! first_height = 2.0e-5        # per-patch layer overrides (wall patches), or yplus = ...
//! [sizing]                     # tangential sizes the layers' front is split to, and the core's
//! adapt = true                 # split/collapse front edges to the tangential sizes (default; --no-adapt)
//! max_size = 0.5               # with max_size or regions: a sizing field (see `crate::sizing`)
//! gradation = 1.2              # core sizes grow by 0.2 per unit length from the front's (1 < g <= 3)
//! [[sizing.regions]]
//! shape = "sphere"             # or "box" with min = [..], max = [..]
//! center = [0.0, 0.0, 0.0]
//! radius = 1.1
//! size = 0.02
//! [core]
//! mesher = "tetgen"            # or "native" (Delaunay, boundary recovery, refinement; --core-mesher)
//! [flow_conditions]            # for yplus: Re on a reference length (heights in its units)
//! reynolds = 14.6e6
//! length = 646.07
//! # velocity, density, viscosity: all three or none, same unit system as length
//! ```

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::yplus::FlowConditions;

/// Default first-layer height, as a fraction of the bounding-box diagonal.
pub const DEFAULT_FIRST_HEIGHT_REL: f64 = 1e-3;
pub const DEFAULT_GROWTH: f64 = 1.2;
pub const DEFAULT_LAYER_COUNT: u32 = 10;
/// Default [`LayerSettings::first_aspect`].
pub const DEFAULT_FIRST_ASPECT: f64 = 2.0;
pub const DEFAULT_FEATURE_ANGLE: f64 = 30.0;
pub const DEFAULT_FAN_ANGLE: f64 = 20.0;

/// Marches again at most to mend the core's slivers by peeling stacks (`peel_rounds`). Spot
/// (H = 1e-3 D, 10 layers) needed 4 or 5 of them to leave none (growth 1.1999 / 1.2 / 1.2001),
/// the flange 3, the ONERA M6 1 (at 1.2001).
pub const DEFAULT_PEEL_ROUNDS: usize = 8;
/// More layers than this is certainly a mistake (and a memory blow-up).
pub const MAX_LAYER_COUNT: u32 = 1000;
/// With `count = "auto"`, the most layers a column gets when its cells never become isotropic
/// (a given `thickness` caps the stack instead).
pub const AUTO_MAX_LAYERS: u32 = 60;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Flow {
    /// The fluid is outside the surface's shells (a body in a farfield).
    #[default]
    External,
    /// The surface bounds the fluid (a duct): layers grow inward, there is no farfield.
    Internal,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FarfieldShape {
    #[default]
    Box,
    Sphere,
}

/// What a patch is, for the mesher.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    /// Viscous wall: gets layers.
    #[default]
    Wall,
    /// A plane the layers slide along (their columns there stay on it). The cut face of a body
    /// in an external flow: the farfield becomes a half box whose face on the plane is the
    /// symmetry patch.
    Symmetry,
    Farfield,
    Inlet,
    Outlet,
    /// Any other boundary without layers. On every patch without layers that is planar, the
    /// columns of the walls around it slide in its plane, so the layers end against it.
    None,
}

impl Role {
    pub fn has_layers(self) -> bool {
        self == Role::Wall
    }
}

/// How many layers: a fixed count, or until the cells become isotropic.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum LayerCount {
    Fixed(u32),
    Auto,
}

impl<'de> Deserialize<'de> for LayerCount {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Raw {
            Int(i64),
            Text(String),
        }
        match Raw::deserialize(d)? {
            Raw::Int(n) if (1..=MAX_LAYER_COUNT as i64).contains(&n) => Ok(LayerCount::Fixed(n as u32)),
            Raw::Int(n) => Err(serde::de::Error::custom(format!(
                "layer count {n} is out of range 1..={MAX_LAYER_COUNT}"
            ))),
            Raw::Text(s) => s.parse().map_err(serde::de::Error::custom),
        }
    }
}

impl std::str::FromStr for LayerCount {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s.eq_ignore_ascii_case("auto") {
            return Ok(LayerCount::Auto);
        }
        match s.parse::<u32>() {
            Ok(n) if (1..=MAX_LAYER_COUNT).contains(&n) => Ok(LayerCount::Fixed(n)),
            _ => Err(format!("layer count must be 1..={MAX_LAYER_COUNT} or \"auto\", got {s:?}")),
        }
    }
}

/// Layer settings as the user wrote them; every field optional.
#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LayerSettings {
    pub first_height: Option<f64>,
    pub growth: Option<f64>,
    pub count: Option<LayerCount>,
    pub thickness: Option<f64>,
    /// After a fixed count (or thickness), go on growing at the same rate until the cells are
    /// isotropic, so that the core starts at the last layer's size (default true).
    pub transition: Option<bool>,
    /// The least ratio of the wall's edge length at a vertex to its first layer's height
    /// (default [`DEFAULT_FIRST_ASPECT`]; 0 turns it off), kept where stacks stop short: where
    /// the wall is faceted finer than that (a blunt trailing edge, a wing tip's cap) and the
    /// stack stopped, the layers are marched again with the first height there lowered to fit
    /// and graded back over the wall at the growth rate. A first cell taller than its wall
    /// triangle is wide turns over where the wall curves at its own edge scale, and the stack
    /// there gets no layer at all. Where the stacks stand, the height asked is kept.
    pub first_aspect: Option<f64>,
}

impl LayerSettings {
    /// Fields set in `over` replace ours.
    pub fn overridden_by(&self, over: &LayerSettings) -> LayerSettings {
        LayerSettings {
            first_height: over.first_height.or(self.first_height),
            growth: over.growth.or(self.growth),
            // A count and a thickness exclude each other: the more specific source wins both.
            count: if over.thickness.is_some() { over.count } else { over.count.or(self.count) },
            thickness: if over.count.is_some() { over.thickness } else { over.thickness.or(self.thickness) },
            transition: over.transition.or(self.transition),
            first_aspect: over.first_aspect.or(self.first_aspect),
        }
    }
}

/// Settings for the patches whose name matches `match` (a regex matched against the whole name).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PatchRule {
    #[serde(rename = "match")]
    pub pattern: String,
    #[serde(default)]
    pub role: Option<Role>,
    #[serde(flatten)]
    pub layers: LayerSettings,
}

/// The whole configuration, as read from TOML and overridden by flags.
#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    #[serde(default)]
    pub flow: Flow,
    #[serde(default)]
    pub farfield: FarfieldShape,
    pub feature_angle: Option<f64>,
    pub fan_angle: Option<f64>,
    #[serde(default)]
    pub layers: LayerSettings,
    #[serde(default, rename = "patch")]
    pub patches: Vec<PatchRule>,
    #[serde(default)]
    pub sizing: SizingSettings,
    #[serde(default)]
    pub core: CoreSettings,
    /// Marches again at most with the stacks under the core's slivers a layer lower
    /// (default [`DEFAULT_PEEL_ROUNDS`]; 0: none).
    pub peel_rounds: Option<usize>,
}

/// The core fill's settings.
#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CoreSettings {
    /// Which mesher fills the core (default [`CoreMesherChoice::TetGen`]).
    pub mesher: Option<CoreMesherChoice>,
}

/// The core mesher.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum CoreMesherChoice {
    /// TetGen 1.5 (cargo feature `tetgen`), with its refinement and optimisation.
    #[default]
    TetGen,
    /// The native mesher (`crate::fill::recover`): Delaunay, boundary recovery and the guide's
    /// points; no refinement to the sizes yet.
    Native,
}

impl std::str::FromStr for CoreMesherChoice {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "tetgen" => Ok(CoreMesherChoice::TetGen),
            "native" => Ok(CoreMesherChoice::Native),
            _ => Err(format!("core mesher must be \"tetgen\" or \"native\", got {s:?}")),
        }
    }
}

/// The sizes the layers' front is kept to while it marches (tangential adaptivity).
#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SizingSettings {
    /// Split front edges that grow too long (default true).
    pub adapt: Option<bool>,
    /// Largest size anywhere (default: the body size).
    pub max_size: Option<f64>,
    /// Sizes grow by at most `gradation - 1` per unit length away from where they are set.
    pub gradation: Option<f64>,
    /// Where the user wants given isotropic sizes.
    #[serde(default)]
    pub regions: Vec<crate::sizing::Region>,
}

impl SizingSettings {
    /// Whether the front's edges are split and collapsed to the tangential sizes as they march
    /// (on unless the user turns it off): to the sizing field's sizes when there is one, else
    /// to the wall's own. With the edge-own wall length rules of [`crate::layers::split::Sizes`]
    /// it raises the coverage at concave ridges where fronts compress (measure.py resolution
    /// coverage at concave ridges, H = 1e-3 D, 10 layers, without -> with: fandisk 0.835 ->
    /// 0.923, mech 0.607 -> 0.627, spot 0.857 -> 0.874, arrow 0.660 -> 0.677; flange 0.947 ->
    /// 0.933).
    pub fn adapt(&self) -> bool {
        self.adapt.unwrap_or(true)
    }

    /// The sizing field's spec when the user asked for one (a maximum size or regions), with the
    /// layer law of `layers`; `None` keeps the front to the wall's own sizes.
    pub fn field_spec(&self, layers: &LayerSpec, body_size: f64) -> Option<crate::sizing::SizingSpec> {
        (self.max_size.is_some() || !self.regions.is_empty()).then(|| crate::sizing::SizingSpec {
            first_height: layers.first_height,
            growth: layers.growth,
            max_size: self.max_size.unwrap_or(body_size),
            gradation: self.gradation.unwrap_or(crate::sizing::DEFAULT_GRADATION),
            regions: self.regions.clone(),
        })
    }
}

#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error("{}: cannot read: {source}", path.display())]
    Io { path: std::path::PathBuf, source: std::io::Error },
    #[error("{}: {message}", path.display())]
    Syntax { path: std::path::PathBuf, message: String },
    #[error("invalid parameter {name} = {value}: {why}")]
    Parameter { name: String, value: String, why: String },
    #[error("[[patch]] match = {pattern:?} is not a valid regex: {why}")]
    Pattern { pattern: String, why: String },
}

fn bad(name: &str, value: impl ToString, why: &str) -> ConfigError {
    ConfigError::Parameter { name: name.into(), value: value.to_string(), why: why.into() }
}

impl Config {
    pub fn from_toml_file(path: &Path) -> Result<Config, ConfigError> {
        let text = std::fs::read_to_string(path)
            .map_err(|source| ConfigError::Io { path: path.to_owned(), source })?;
        Self::from_toml_str(&text).map_err(|message| ConfigError::Syntax { path: path.to_owned(), message })
    }

    /// Parse a config; `yplus` keys are resolved into `first_height` with `[flow_conditions]`.
    pub fn from_toml_str(text: &str) -> Result<Config, String> {
        let table: toml::Table = toml::from_str(text).map_err(|e| e.to_string())?;
        if !has_yplus(&table) {
            // Deserializing the text itself keeps line numbers in the errors.
            return toml::from_str(text).map_err(|e| e.to_string());
        }
        Self::from_table(table)
    }

    /// A config given as a table of the TOML file's keys (the Python package's `config=` dict,
    /// which arrives as JSON).
    pub fn from_table(mut table: toml::Table) -> Result<Config, String> {
        resolve_yplus(&mut table).map_err(|e| e.to_string())?;
        table.try_into().map_err(|e: toml::de::Error| e.to_string().trim_end().to_owned())
    }

    pub fn feature_angle(&self) -> f64 {
        self.feature_angle.unwrap_or(DEFAULT_FEATURE_ANGLE)
    }

    pub fn fan_angle(&self) -> f64 {
        self.fan_angle.unwrap_or(DEFAULT_FAN_ANGLE)
    }

    pub fn peel_rounds(&self) -> usize {
        self.peel_rounds.unwrap_or(DEFAULT_PEEL_ROUNDS)
    }

    /// Check everything that does not depend on the surface.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let fa = self.feature_angle();
        if !(fa.is_finite() && fa > 0.0 && fa < 180.0) {
            return Err(bad("feature_angle", fa, "must be between 0 and 180 degrees"));
        }
        let fan = self.fan_angle();
        if !(fan.is_finite() && fan >= 1.0 && fan <= 90.0) {
            return Err(bad("fan_angle", fan, "must be between 1 and 90 degrees"));
        }
        if let Some(g) = self.sizing.gradation {
            // At 1 the core would be as fine as the finest front everywhere.
            if !(g.is_finite() && g > 1.0 && g <= 3.0) {
                return Err(bad("sizing.gradation", g, "must be a ratio above 1 and at most 3"));
            }
        }
        if let Some(m) = self.sizing.max_size {
            if !(m.is_finite() && m > 0.0) {
                return Err(bad("sizing.max_size", m, "must be a positive length"));
            }
        }
        validate_layer_settings("layers", &self.layers)?;
        for rule in &self.patches {
            regex::Regex::new(&rule.pattern)
                .map_err(|e| ConfigError::Pattern { pattern: rule.pattern.clone(), why: e.to_string() })?;
            validate_layer_settings(&format!("patch {:?}", rule.pattern), &rule.layers)?;
        }
        Ok(())
    }

    /// The `[[patch]]` patterns that match none of `patch_names` (most likely a mistake).
    pub fn unmatched_rules(&self, patch_names: &[String]) -> Vec<&str> {
        self.patches
            .iter()
            .filter(|rule| {
                let whole = format!("^(?:{})$", rule.pattern);
                regex::Regex::new(&whole).is_ok_and(|re| !patch_names.iter().any(|n| re.is_match(n)))
            })
            .map(|rule| rule.pattern.as_str())
            .collect()
    }

    /// Role and layer settings of a patch: the last matching `[[patch]]` rule wins.
    pub fn patch_settings(&self, patch_name: &str) -> (Role, LayerSettings) {
        let mut role = Role::Wall;
        let mut layers = self.layers.clone();
        for rule in &self.patches {
            let whole = format!("^(?:{})$", rule.pattern);
            if regex::Regex::new(&whole).is_ok_and(|re| re.is_match(patch_name)) {
                role = rule.role.unwrap_or(role);
                layers = layers.overridden_by(&rule.layers);
            }
        }
        (role, layers)
    }
}

/// Whether the config uses `yplus` (or gives `[flow_conditions]` for it).
fn has_yplus(table: &toml::Table) -> bool {
    let in_table = |v: &toml::Value| v.as_table().is_some_and(|t| t.contains_key("yplus"));
    table.contains_key("flow_conditions")
        || table.get("layers").is_some_and(in_table)
        || table.get("patch").and_then(toml::Value::as_array).is_some_and(|a| a.iter().any(in_table))
}

/// Replace every `yplus` (in `[layers]` and `[[patch]]`) by the `first_height` it gives at the
/// `[flow_conditions]`, and remove that table.
fn resolve_yplus(table: &mut toml::Table) -> Result<(), ConfigError> {
    let flow = match table.remove("flow_conditions") {
        Some(value) => Some(
            FlowConditions::deserialize(value)
                .map_err(|e| bad("flow_conditions", "(table)", &e.to_string()))?,
        ),
        None => None,
    };
    if let Some(toml::Value::Table(layers)) = table.get_mut("layers") {
        resolve_yplus_in("layers", layers, flow.as_ref())?;
    }
    if let Some(toml::Value::Array(patches)) = table.get_mut("patch") {
        for (i, patch) in patches.iter_mut().enumerate() {
            if let toml::Value::Table(patch) = patch {
                resolve_yplus_in(&format!("patch[{i}]"), patch, flow.as_ref())?;
            }
        }
    }
    Ok(())
}

/// Replace `yplus` in one layer-settings table (`what` names it in errors), if it is there.
fn resolve_yplus_in(
    what: &str,
    layers: &mut toml::Table,
    flow: Option<&FlowConditions>,
) -> Result<(), ConfigError> {
    let Some(yplus) = layers.remove("yplus") else { return Ok(()) };
    let name = format!("{what}.yplus");
    let yplus = yplus.as_float().or(yplus.as_integer().map(|i| i as f64));
    let yplus = yplus.ok_or_else(|| bad(&name, "(not a number)", "must be a number"))?;
    if layers.contains_key("first_height") {
        return Err(bad(&name, yplus, "give either first_height or yplus, not both"));
    }
    let flow = flow.ok_or_else(|| bad(&name, yplus, "needs a [flow_conditions] table"))?;
    let height = flow.first_height(yplus)?.height;
    layers.insert("first_height".into(), toml::Value::Float(height));
    Ok(())
}

fn validate_layer_settings(what: &str, s: &LayerSettings) -> Result<(), ConfigError> {
    let name = |field: &str| format!("{what}.{field}");
    if let Some(h) = s.first_height {
        if !(h.is_finite() && h > 0.0) {
            return Err(bad(&name("first_height"), h, "must be a positive length"));
        }
    }
    if let Some(r) = s.growth {
        if !(r.is_finite() && (1.0..=5.0).contains(&r)) {
            return Err(bad(&name("growth"), r, "must be between 1 and 5"));
        }
    }
    if let Some(a) = s.first_aspect {
        if !(a.is_finite() && a >= 0.0) {
            return Err(bad(&name("first_aspect"), a, "must be a ratio of 0 (off) or more"));
        }
    }
    if let Some(t) = s.thickness {
        if !(t.is_finite() && t > 0.0) {
            return Err(bad(&name("thickness"), t, "must be a positive length"));
        }
        if s.count.is_some() {
            return Err(bad(&name("thickness"), t, "give either a layer count or a thickness, not both"));
        }
        if let Some(h) = s.first_height.filter(|&h| t < h) {
            return Err(bad(&name("thickness"), t, &format!("is thinner than the first layer ({h})")));
        }
    }
    Ok(())
}

/// The layer stack of one patch, with every value resolved and checked.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LayerSpec {
    pub first_height: f64,
    pub growth: f64,
    pub count: LayerCount,
    /// Transition layers after a fixed count ([`LayerSettings::transition`]).
    pub transition: bool,
    /// [`LayerSettings::first_aspect`].
    pub first_aspect: f64,
    /// See [`LayerSpec::max_count`].
    max_count: u32,
}

#[cfg(test)]
impl LayerSpec {
    /// `count` layers from `first_height` growing by `growth`, no transition layers (for tests).
    pub(crate) fn fixed(first_height: f64, growth: f64, count: u32) -> LayerSpec {
        let settings = LayerSettings {
            first_height: Some(first_height),
            growth: Some(growth),
            count: Some(LayerCount::Fixed(count)),
            thickness: None,
            transition: Some(false),
            first_aspect: None,
        };
        LayerSpec::resolve(&settings, 1.0).expect("valid test settings")
    }
}

impl LayerSpec {
    /// Resolve user settings against the body size (bounding-box diagonal).
    pub fn resolve(s: &LayerSettings, body_size: f64) -> Result<LayerSpec, ConfigError> {
        let first_height = s.first_height.unwrap_or(DEFAULT_FIRST_HEIGHT_REL * body_size);
        let growth = s.growth.unwrap_or(DEFAULT_GROWTH);
        let count = match (s.count, s.thickness) {
            (Some(c), _) => c,
            (None, Some(t)) => LayerCount::Fixed(layers_for_thickness(first_height, growth, t)?),
            (None, None) => LayerCount::Fixed(DEFAULT_LAYER_COUNT),
        };
        let transition = s.transition.unwrap_or(true);
        let max_count = match (count, s.thickness) {
            (LayerCount::Fixed(n), _) if transition => n.max(AUTO_MAX_LAYERS),
            (LayerCount::Fixed(n), _) => n,
            (LayerCount::Auto, Some(t)) => layers_for_thickness(first_height, growth, t)?,
            (LayerCount::Auto, None) => AUTO_MAX_LAYERS,
        };
        let first_aspect = s.first_aspect.unwrap_or(DEFAULT_FIRST_ASPECT);
        Ok(LayerSpec { first_height, growth, count, transition, first_aspect, max_count })
    }

    /// The most layers a column gets: the fixed count (with transition layers: the cap of an
    /// automatic count, or the fixed count if more), or the cap of an automatic one.
    pub fn max_count(&self) -> u32 {
        self.max_count
    }

    /// The same stack ending at its count: no transition layers.
    pub fn without_transition(self) -> LayerSpec {
        match self.count {
            LayerCount::Fixed(n) => LayerSpec { transition: false, max_count: n, ..self },
            LayerCount::Auto => LayerSpec { transition: false, ..self },
        }
    }

    /// The layers of a full stack, what coverage is measured against: the fixed count (the
    /// transition layers after it are extra), or the cap of an automatic one.
    pub fn full_count(&self) -> u32 {
        match self.count {
            LayerCount::Fixed(n) => n,
            LayerCount::Auto => self.max_count,
        }
    }

    /// Whether layer `k` (1-based) ends where its cells would be isotropic: every layer of an
    /// automatic count, the transition layers after a fixed one.
    pub fn stops_when_isotropic(&self, k: u32) -> bool {
        match self.count {
            LayerCount::Fixed(n) => self.transition && k > n,
            LayerCount::Auto => true,
        }
    }

    /// Height of layer `k` (0-based).
    pub fn height(&self, k: u32) -> f64 {
        self.first_height * self.growth.powi(k as i32)
    }

    /// Distance from the wall of the top of layer `k - 1` (the sum of the first `k` heights).
    pub fn distance(&self, k: u32) -> f64 {
        if self.growth == 1.0 {
            self.first_height * k as f64
        } else {
            self.first_height * (self.growth.powi(k as i32) - 1.0) / (self.growth - 1.0)
        }
    }
}

/// The fewest layers whose total height reaches `thickness`.
fn layers_for_thickness(h0: f64, r: f64, thickness: f64) -> Result<u32, ConfigError> {
    if thickness < h0 {
        return Err(bad("thickness", thickness, &format!("is thinner than the first layer ({h0})")));
    }
    let n = if r == 1.0 {
        (thickness / h0).ceil()
    } else {
        ((1.0 + thickness * (r - 1.0) / h0).ln() / r.ln()).ceil()
    };
    if n > MAX_LAYER_COUNT as f64 {
        return Err(bad("thickness", thickness, &format!("needs {n} layers, more than {MAX_LAYER_COUNT}")));
    }
    Ok((n as u32).max(1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_documented_example() {
        let c = Config::from_toml_str(
            r#"
            flow = "external"
            farfield = "box"
            [layers]
            first_height = 1.0e-5
            growth = 1.2
            count = 25
            [[patch]]
            match = "face9"
            role = "symmetry"
            [[patch]]
            match = "fin[0-9]"
            first_height = 2.0e-5
            count = "auto"
            "#,
        )
        .unwrap();
        c.validate().unwrap();
        assert_eq!(c.patch_settings("face9").0, Role::Symmetry);
        assert_eq!(c.patch_settings("face90").0, Role::Wall, "match is on the whole name");
        let (role, fin) = c.patch_settings("fin3");
        assert_eq!(role, Role::Wall);
        assert_eq!(fin.first_height, Some(2.0e-5));
        assert_eq!(fin.count, Some(LayerCount::Auto));
        assert_eq!(fin.growth, Some(1.2));
    }

    #[test]
    fn rejects_impossible_parameters() {
        let bad_cases = [
            "[layers]\nfirst_height = -1.0",
            "[layers]\ngrowth = 0.9",
            "[layers]\nfirst_height = 1.0\nthickness = 0.5",
            "[layers]\ncount = 5\nthickness = 0.5",
            "[layers]\nfirst_aspect = -1.0",
            "[[patch]]\nmatch = \"wing\"\nfirst_aspect = nan",
            "feature_angle = 200.0",
            "[[patch]]\nmatch = \"(\"",
            "[sizing]\ngradation = 1.0",
            "[sizing]\ngradation = 4.0",
            "[sizing]\nmax_size = 0.0",
        ];
        for text in bad_cases {
            let c = Config::from_toml_str(text).unwrap();
            assert!(c.validate().is_err(), "accepted: {text}");
        }
        assert!(Config::from_toml_str("[layers]\ncount = 0").is_err());
        assert!(Config::from_toml_str("[layers]\ncount = \"many\"").is_err());
        assert!(Config::from_toml_str("unknown_key = 1").is_err());
    }

    /// A fixed count goes on to isotropy after its layers unless `transition = false`; the
    /// full stack stays the count.
    #[test]
    fn transition_layers_follow_a_fixed_count() {
        let spec = |toml: &str| {
            let c = Config::from_toml_str(toml).unwrap();
            LayerSpec::resolve(&c.layers, 1.0).unwrap()
        };
        let on = spec("[layers]\ncount = 8\n");
        assert!(on.transition && on.full_count() == 8 && on.max_count() == AUTO_MAX_LAYERS);
        assert!(!on.stops_when_isotropic(8) && on.stops_when_isotropic(9));
        let off = spec("[layers]\ncount = 8\ntransition = false\n");
        assert!(off.full_count() == 8 && off.max_count() == 8 && !off.stops_when_isotropic(9));
        let auto = spec("[layers]\ncount = \"auto\"\n");
        assert!(auto.stops_when_isotropic(1) && auto.full_count() == AUTO_MAX_LAYERS);
        assert_eq!(spec("[layers]\ncount = 80\n").max_count(), 80);
    }

    #[test]
    fn yplus_resolves_the_first_height_from_the_flow_conditions() {
        let c = Config::from_toml_str(
            "[layers]\nyplus = 1.0\ncount = 25\n[flow_conditions]\nreynolds = 14.6e6\nlength = 646.07\n\
             [[patch]]\nmatch = \"fin\"\nyplus = 2\n",
        )
        .unwrap();
        c.validate().unwrap();
        let h = c.layers.first_height.unwrap();
        assert!((h - 1.26734e-3).abs() < 1e-8, "{h}"); // mm, see crate::yplus
        let fin = c.patch_settings("fin").1.first_height.unwrap();
        assert!((fin - 2.0 * h).abs() < 1e-15);
        let errors = [
            ("[layers]\nyplus = 1.0", "needs a [flow_conditions]"),
            (
                "[layers]\nyplus = 1.0\nfirst_height = 1e-3\n[flow_conditions]\nreynolds = 1e6\nlength = 1.0",
                "not both",
            ),
            ("[layers]\nyplus = -1.0\n[flow_conditions]\nreynolds = 1e6\nlength = 1.0", "yplus"),
            ("[layers]\nyplus = 1.0\n[flow_conditions]\nreynolds = 1e6", "length"),
            ("[flow_conditions]\nreynolds = 1e6\nlength = 1.0\nspeed = 3.0", "unknown field"),
        ];
        for (text, expected) in errors {
            let e = Config::from_toml_str(text).unwrap_err();
            assert!(e.contains(expected), "{text}: {e}");
        }
    }

    #[test]
    fn thickness_gives_the_fewest_layers_reaching_it() {
        let s = LayerSettings {
            first_height: Some(1.0),
            growth: Some(2.0),
            thickness: Some(7.0),
            count: None,
            transition: None,
            first_aspect: None,
        };
        let spec = LayerSpec::resolve(&s, 1.0).unwrap();
        assert_eq!(spec.count, LayerCount::Fixed(3)); // 1 + 2 + 4 = 7
        assert_eq!(spec.distance(3), 7.0);
        let s = LayerSettings { thickness: Some(7.5), ..s };
        assert_eq!(LayerSpec::resolve(&s, 1.0).unwrap().count, LayerCount::Fixed(4));
    }

    #[test]
    fn defaults_scale_with_the_body() {
        let a = LayerSpec::resolve(&LayerSettings::default(), 1.0).unwrap();
        let b = LayerSpec::resolve(&LayerSettings::default(), 1000.0).unwrap();
        assert!((b.first_height / a.first_height - 1000.0).abs() < 1e-9);
        assert_eq!(a.count, b.count);
    }
}
