//! Which estimators make a scene's image, decided here from the scene alone, and the versioned
//! list of tokens that names them (docs/caustics.md, "Who owns which paths").
//!
//! The camera paths always run. With `[pathtrace] caustics = true`, a directional light and a
//! mirror or dielectric object, the light tracer adds the paths L S+ D E; with a delta sun and a
//! diffuse surface to gather on, the photon gather adds L S+ D (S|D)+ E and the host's glint
//! solve adds L S* E (a sun disc is found by the camera paths themselves).
//!
//! Checkpoints, `merge` and cached truths compare the token list ([`Estimators::key`]): samples
//! made by another set of estimators, or by another rule of one of them, hold other light, so
//! they must not be added together. A token names an estimator and, where it has one, the
//! version of its rule; the first token is the list's own version. A change of what any
//! estimator computes changes its token, never only a comment.
//!
//! A leaf: it depends on the scene model alone, so the tracer, the glint, the shaders'
//! specialisation and the metadata all ask it, and it asks none of them.

use illum_scene::specular_spheres::solvable_spheres;
use illum_scene::{CausticMethod, Feature, MaterialKind, Scene};

/// The token list's own version: its first token.
pub const KEY_VERSION: &str = "estimators.v1";

/// r_1 of the photon gather as a fraction of the largest specular object's bounding radius
/// (docs/caustics-gather.md, "Radius"); the oracle's gather uses the same.
pub const GATHER_RADIUS_FRACTION: f32 = 0.02;

/// The photon gather's radius rule, r_j = r_1 (j + 1)^(-1/6) with j counted from the render's first
/// sample index (`gather_radius` in caustic_buffers.wgsl). Its first rule, counted from sample
/// index 0, made a part of a split render that starts far from 0 gather at a much smaller radius
/// than its own count of samples would, with a dishonest error estimate.
const GATHER_TOKEN: &str = "photon-gather.r2";

/// Manifold next-event estimation's rule: chains R, T T, T R T per sphere, the grid and the bound
/// on the concentration of `manifold.wgsl`.
const MANIFOLD_TOKEN: &str = "manifold-nee.v1";

/// One estimator.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Estimator {
    /// Camera paths with next-event estimation: every scene.
    CameraPaths,
    /// Particles from the sun, connected to the eye: L S+ D E.
    LightTracer,
    /// Photons of the light tracer gathered along camera paths: L S+ D (S|D)+ E.
    PhotonGather,
    /// The sun's glint solved on the host and added to its pixel's mean: L S* E.
    GlintSolve,
    /// Manifold next-event estimation through one sphere (`shaders/manifold.wgsl`): at every
    /// diffuse vertex, the sun's light through each specular sphere's chains R, T T and T R T,
    /// solved: L S+ D (S|D)* E with the chain on one sphere.
    ManifoldNee,
}

impl Estimator {
    /// Its token in [`Estimators::key`].
    pub fn token(self) -> &'static str {
        match self {
            Estimator::CameraPaths => "camera-paths",
            Estimator::LightTracer => "light-tracer",
            Estimator::PhotonGather => GATHER_TOKEN,
            Estimator::GlintSolve => "glint-solve",
            Estimator::ManifoldNee => MANIFOLD_TOKEN,
        }
    }
}

/// The estimators of one scene's image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct Estimators {
    manifold: bool,
    light_tracer: bool,
    photon_gather: bool,
    glint: bool,
}

impl Estimators {
    /// The estimators `scene` is rendered with.
    pub fn of(scene: &Scene) -> Self {
        let specular = scene.objects.iter().any(|o| {
            matches!(scene.material_of(o).kind, MaterialKind::Mirror { .. } | MaterialKind::Dielectric { .. })
        });
        let diffuse = scene.features().any(&[Feature::Lambertian, Feature::Checker]);
        let wanted = scene.pathtrace.caustics
            && scene.directional_light.is_some()
            && specular
            && Self::mesh_stops_caustics(scene).is_none();
        let delta_sun = scene.directional_light.is_some_and(|l| l.is_delta());
        // Asked for and solvable, the solve replaces the light tracer and its gather
        // (docs/caustics-manifold.md, "What it leaves out").
        let manifold = wanted
            && diffuse
            && Self::manifold_falls_back(scene).is_none()
            && scene.pathtrace.caustic_method == CausticMethod::Manifold;
        let light_tracer = wanted && !manifold;
        Estimators {
            manifold,
            light_tracer,
            photon_gather: light_tracer && delta_sun && diffuse,
            glint: wanted && delta_sun,
        }
    }

    /// Why `caustic_method = "manifold"` falls back to the light tracer for `scene`: the
    /// reason [`solvable_spheres`] gives. `None` when the solve runs, or was not asked for.
    pub fn manifold_falls_back(scene: &Scene) -> Option<String> {
        if scene.pathtrace.caustic_method != CausticMethod::Manifold || !scene.pathtrace.caustics {
            return None;
        }
        solvable_spheres(scene)
            .err()
            .map(|why| format!("caustic method manifold falls back to the light tracer: {why}"))
    }

    /// Why the caustic's estimators are off although the scene asks for them: they follow light
    /// through spheres (their particles aim at specular objects' bounding spheres, the glint is
    /// solved on spheres and quads), so a scene with a mesh renders with camera paths alone,
    /// which miss the sun's caustic (docs/caustics.md).
    pub fn mesh_stops_caustics(scene: &Scene) -> Option<&'static str> {
        let mesh = scene.features().contains(Feature::MeshShape);
        (scene.pathtrace.caustics && mesh).then_some(
            "caustics off: the caustic's estimators do not follow light through meshes; camera paths \
             alone miss the sun's caustic",
        )
    }

    /// Manifold next-event estimation (shader def MANIFOLD).
    pub fn manifold(&self) -> bool {
        self.manifold
    }

    /// The caustic's light tracer (and the shaders' CAUSTIC code).
    pub fn light_tracer(&self) -> bool {
        self.light_tracer
    }

    /// The photon gather (shader def CAUSTIC_GATHER).
    pub fn photon_gather(&self) -> bool {
        self.photon_gather
    }

    /// The glint's solve on the host.
    pub fn glint(&self) -> bool {
        self.glint
    }

    /// Whether any of the caustic's estimators runs: `on` or `off` in the metadata's
    /// `illum.caustics` ([`Self::caustics_label`]).
    pub fn caustics(&self) -> bool {
        self.light_tracer || self.manifold
    }

    /// `on` or `off`, as EXR metadata and checkpoints store [`Self::caustics`].
    pub fn caustics_label(&self) -> &'static str {
        if self.caustics() { "on" } else { "off" }
    }

    /// What a render's summary line says of the caustic: `off`, `on (light tracer)` or
    /// `on (manifold NEE)`, so that a user who asked for the solve sees whether it ran or fell
    /// back.
    pub fn caustics_description(&self) -> &'static str {
        if self.manifold {
            "on (manifold NEE)"
        } else if self.light_tracer {
            "on (light tracer)"
        } else {
            "off"
        }
    }

    /// The estimators that run, camera paths first.
    pub fn list(&self) -> Vec<Estimator> {
        let mut list = vec![Estimator::CameraPaths];
        let optional = [
            (self.manifold, Estimator::ManifoldNee),
            (self.light_tracer, Estimator::LightTracer),
            (self.photon_gather, Estimator::PhotonGather),
            (self.glint, Estimator::GlintSolve),
        ];
        list.extend(optional.iter().filter(|(on, _)| *on).map(|(_, e)| *e));
        list
    }

    /// The versioned token list: [`KEY_VERSION`], then each estimator's token, space-separated
    /// (for example `estimators.v1 camera-paths light-tracer photon-gather.r2 glint-solve`).
    pub fn key(&self) -> String {
        std::iter::once(KEY_VERSION)
            .chain(self.list().into_iter().map(Estimator::token))
            .collect::<Vec<_>>()
            .join(" ")
    }
}

/// Why a stored estimator key cannot be compared with this build's.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum KeyMismatch {
    /// The file names its estimators in an older form: `caustic_estimators`, an English sentence,
    /// before the token list, or a list of another version.
    OlderForm { found: String },
    /// Both are token lists of this version, and these tokens differ.
    Tokens { only_in_file: Vec<String>, only_now: Vec<String> },
}

impl std::fmt::Display for KeyMismatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            KeyMismatch::OlderForm { found } => write!(
                f,
                "the file names its estimators in an older form ({found}), not the token list {KEY_VERSION}: its \
                 samples may hold other light (an older radius rule of the photon gather, or fewer estimators), so \
                 they cannot be added to this render's; render it again"
            ),
            KeyMismatch::Tokens { only_in_file, only_now } => write!(
                f,
                "the file's estimators differ: {} in the file only, {} in this render only",
                list_or_none(only_in_file),
                list_or_none(only_now)
            ),
        }
    }
}

fn list_or_none(tokens: &[String]) -> String {
    if tokens.is_empty() { "none".to_owned() } else { tokens.join(", ") }
}

/// Checks that a stored key (`None`: the file has none, and `legacy` is its `caustic_estimators`
/// sentence, if any) is a token list of this version, and returns its tokens.
pub fn stored_tokens<'a>(stored: Option<&'a str>, legacy: Option<&str>) -> Result<Vec<&'a str>, KeyMismatch> {
    let Some(stored) = stored else {
        let found = match legacy {
            Some(sentence) => format!("illum.caustic_estimators = {sentence:?}"),
            None => "no illum.estimators field".to_owned(),
        };
        return Err(KeyMismatch::OlderForm { found });
    };
    let tokens: Vec<&str> = stored.split_whitespace().collect();
    if tokens.first() != Some(&KEY_VERSION) {
        return Err(KeyMismatch::OlderForm { found: format!("illum.estimators = {stored:?}") });
    }
    Ok(tokens)
}

/// Compares a stored key ([`stored_tokens`]) with `now`'s. `Ok` when they name the same
/// estimators by the same rules, in any order.
pub fn compare_key(stored: Option<&str>, legacy: Option<&str>, now: &Estimators) -> Result<(), KeyMismatch> {
    let tokens = stored_tokens(stored, legacy)?;
    let key = now.key();
    let current: Vec<&str> = key.split_whitespace().collect();
    let only_in_file: Vec<String> =
        tokens.iter().filter(|t| !current.contains(t)).map(|t| t.to_string()).collect();
    let only_now: Vec<String> =
        current.iter().filter(|t| !tokens.contains(t)).map(|t| t.to_string()).collect();
    if only_in_file.is_empty() && only_now.is_empty() {
        Ok(())
    } else {
        Err(KeyMismatch::Tokens { only_in_file, only_now })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn whitted() -> Scene {
        illum_scene::testing::shipped_scene("whitted.toml", 64, 36)
    }

    #[test]
    fn the_whitted_scene_has_every_estimator_and_the_cornell_box_the_camera_paths_alone() {
        let scene = whitted();
        let all = Estimators::of(&scene);
        assert_eq!(all.key(), "estimators.v1 camera-paths light-tracer photon-gather.r2 glint-solve");
        assert_eq!(all.caustics_label(), "on");
        assert_eq!(all.caustics_description(), "on (light tracer)");
        let mut solved = scene.clone();
        solved.pathtrace.caustic_method = CausticMethod::Manifold;
        assert_eq!(Estimators::of(&solved).caustics_label(), "on");
        assert_eq!(Estimators::of(&solved).caustics_description(), "on (manifold NEE)");
        let mut off = scene.clone();
        off.pathtrace.caustics = false;
        assert_eq!(Estimators::of(&off).key(), "estimators.v1 camera-paths");
        assert_eq!(Estimators::of(&off).caustics_label(), "off");
        assert_eq!(Estimators::of(&off).caustics_description(), "off");
        // A sun disc: the camera paths find the gather's and the glint's paths themselves.
        let mut disc = scene.clone();
        disc.directional_light.as_mut().expect("a sun").angular_radius_deg = 1.0;
        assert_eq!(Estimators::of(&disc).list(), [Estimator::CameraPaths, Estimator::LightTracer]);
        let cornell = illum_scene::testing::shipped_scene("cornell.toml", 64, 64);
        assert_eq!(Estimators::of(&cornell).list(), [Estimator::CameraPaths]);
    }

    /// The oracle's gather (illum-oracle, f64, written apart) uses the tracer's radius rule: the
    /// same r_1 fraction, and the WGSL's exponent is the oracle's (alpha - 1) / 2. (The oracle
    /// renders from sample index 0, where the render's own count and the index agree.)
    #[test]
    fn the_oracles_gather_radius_is_the_tracers() {
        assert_eq!(illum_oracle::gather::RADIUS_FRACTION as f32, GATHER_RADIUS_FRACTION);
        let source = include_str!("../shaders/caustic_buffers.wgsl");
        let exponent: f32 = source
            .split("const RADIUS_EXPONENT: f32 = ")
            .nth(1)
            .and_then(|rest| rest.split(';').next())
            .expect("RADIUS_EXPONENT in caustic_buffers.wgsl")
            .parse()
            .expect("a number");
        assert_eq!(exponent, ((illum_oracle::gather::ALPHA - 1.0) / 2.0) as f32);
        for j in [0u32, 1, 15, 1 << 20] {
            let wgsl = GATHER_RADIUS_FRACTION * (j as f32 + 1.0).powf(exponent);
            let oracle = illum_oracle::gather::radius(illum_oracle::gather::RADIUS_FRACTION, j);
            assert!((f64::from(wgsl) / oracle - 1.0).abs() < 1e-5, "j = {j}: {wgsl} against {oracle}");
        }
    }

    /// Keys compare as token sets of one version; the sentence of the files before the token
    /// list, a missing key or another version are refused by name.
    #[test]
    fn keys_compare_by_tokens_and_older_forms_are_named() {
        let now = Estimators::of(&whitted());
        assert_eq!(compare_key(Some(&now.key()), None, &now), Ok(()));
        // Order does not matter; tokens do.
        let reordered = "estimators.v1 glint-solve camera-paths photon-gather.r2 light-tracer";
        assert_eq!(compare_key(Some(reordered), None, &now), Ok(()));
        let older_rule = "estimators.v1 camera-paths light-tracer photon-gather.r1 glint-solve";
        let mismatch = compare_key(Some(older_rule), None, &now).unwrap_err();
        assert_eq!(
            mismatch,
            KeyMismatch::Tokens {
                only_in_file: vec!["photon-gather.r1".into()],
                only_now: vec!["photon-gather.r2".into()]
            }
        );
        assert!(mismatch.to_string().contains("photon-gather.r1 in the file only"), "{mismatch}");
        let sentence = "light tracer and photon gather at every diffuse vertex; glint solved";
        let old = compare_key(None, Some(sentence), &now).unwrap_err();
        assert!(
            matches!(&old, KeyMismatch::OlderForm { found } if found.contains("caustic_estimators") && found.contains(sentence)),
            "{old:?}"
        );
        assert!(
            old.to_string().contains("render it again") && old.to_string().contains(KEY_VERSION),
            "{old}"
        );
        assert!(matches!(compare_key(None, None, &now), Err(KeyMismatch::OlderForm { .. })));
        assert!(matches!(
            compare_key(Some("estimators.v0 camera-paths"), None, &now),
            Err(KeyMismatch::OlderForm { .. })
        ));
    }
}
