//! The ladder's and Auto's regions, and an image's errors against the reference, overall and
//! per region.
//!
//! Regions are cut from the Whitted ray tracer's object-ID image ([`ObjectIds`]), never drawn by
//! hand: what the pixel's centre ray sees (the sky, an object), and for a diffuse surface
//! whether the scene's first light reaches it or which object's shadow it lies in. On the
//! Whitted scene that gives: sky, floor lit, floor in the glass sphere's shadow, floor in the
//! metal sphere's shadow, glass sphere, metal sphere.
//!
//! The errors of an image against the reference, over a set of pixels:
//! - relMSE, mean over pixels and channels of (a - r)^2 / (r^2 + 0.01) (the same formula as
//!   [`illum_image::rel_mse`]);
//! - the mean luminance ratio, mean luminance of the image over that of the reference (1 for an
//!   unbiased image; a missing light path shows as a ratio below 1);
//! - the mean of a per-pixel visible-difference map when one is given: the ladder gives FLIP's
//!   (`illum_lab::regions::compare`, which needs a C++ library and so stays out of this crate,
//!   which the browser viewer builds).

use std::collections::BTreeMap;

use illum_image::metrics::REL_MSE_EPSILON;
use illum_image::{RgbImage32, luminance};
use illum_scene::{MaterialKind, Scene};
use illum_whitted::{ObjectIds, Shadow};

/// A partition of the image's pixels into named regions.
#[derive(Clone, Debug)]
pub struct Regions {
    pub names: Vec<String>,
    /// Per pixel, row-major from the top-left: the index of its region in `names`.
    pub of_pixel: Vec<usize>,
}

/// The sort key of a region: what is seen, then how it is lit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Key {
    Nothing,
    Object(usize, Lighting),
    /// Every region smaller than [`SMALL_REGION`] of the image, together.
    Small,
}

/// Regions under this fraction of the image are merged into one ("other"): slivers where a
/// pixel's centre ray meets a box's side face or a shadow's single-pixel edge carry no
/// statistics of their own. (The Whitted scene's smallest real region, the metal sphere's
/// shadow, is 1.2% of the image.)
pub const SMALL_REGION: f64 = 0.005;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Lighting {
    /// A surface whose light is not split by shadow (glass, mirror, emitter).
    Whole,
    Lit,
    FacingAway,
    ShadowOf(usize),
}

impl Regions {
    /// The regions of `scene` seen through its camera, from its object-ID image.
    pub fn from_ids(scene: &Scene, ids: &ObjectIds) -> Regions {
        let key = |hit: Option<usize>, shadow: Shadow| match hit {
            None => Key::Nothing,
            Some(k) => {
                let diffuse = matches!(
                    scene.materials[scene.objects[k].material].kind,
                    MaterialKind::Lambertian { .. } | MaterialKind::Checker(_)
                );
                let lighting = match shadow {
                    _ if !diffuse => Lighting::Whole,
                    Shadow::Lit => Lighting::Lit,
                    Shadow::FacingAway => Lighting::FacingAway,
                    Shadow::BlockedBy(j) => Lighting::ShadowOf(j),
                };
                Key::Object(k, lighting)
            }
        };
        let mut keys: Vec<Key> = ids.hit.iter().zip(&ids.shadow).map(|(&h, &s)| key(h, s)).collect();
        let mut counts: BTreeMap<Key, usize> = BTreeMap::new();
        for &k in &keys {
            *counts.entry(k).or_default() += 1;
        }
        let total = keys.len() as f64;
        let small = |k: &Key| (counts[k] as f64) < SMALL_REGION * total;
        for k in &mut keys {
            if small(k) {
                *k = Key::Small;
            }
        }
        let mut order: BTreeMap<Key, usize> = keys.iter().map(|&k| (k, 0)).collect();
        let mut names = Vec::new();
        for (k, index) in order.iter_mut() {
            *index = names.len();
            let object = |i: usize| scene.objects[i].name.clone();
            names.push(match *k {
                Key::Nothing if scene.environment.is_some() => "sky".to_owned(),
                Key::Nothing => "background".to_owned(),
                Key::Object(i, Lighting::Whole) => object(i),
                Key::Object(i, Lighting::Lit) => format!("{}, lit", object(i)),
                Key::Object(i, Lighting::FacingAway) => format!("{}, facing away from the light", object(i)),
                Key::Object(i, Lighting::ShadowOf(j)) => {
                    format!("{} in the {}'s shadow", object(i), object(j))
                }
                Key::Small => format!("other (regions under {}% of the image)", SMALL_REGION * 100.0),
            });
        }
        Regions { names, of_pixel: keys.iter().map(|k| order[k]).collect() }
    }

    /// The index of the region called `name`.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// How many pixels each region has.
    pub fn sizes(&self) -> Vec<usize> {
        let mut sizes = vec![0; self.names.len()];
        for &r in &self.of_pixel {
            sizes[r] += 1;
        }
        sizes
    }
}

/// The pixels of the region called `name`: an object's name in the scene file (every pixel
/// whose centre ray sees it) or one of [`Regions::from_ids`]'s names (e.g. "floor, lit"). An
/// unknown name is refused with the valid ones listed.
pub fn region_mask(scene: &Scene, ids: &ObjectIds, name: &str) -> Result<Vec<bool>, String> {
    if let Some(object) = scene.objects.iter().position(|o| o.name == name) {
        return Ok(ids.hit.iter().map(|&h| h == Some(object)).collect());
    }
    let regions = Regions::from_ids(scene, ids);
    if let Some(index) = regions.index(name) {
        return Ok(regions.of_pixel.iter().map(|&r| r == index).collect());
    }
    let mut valid: Vec<String> = scene.objects.iter().map(|o| o.name.clone()).collect();
    valid.extend(regions.names.iter().filter(|n| !valid.contains(n)).cloned().collect::<Vec<_>>());
    let valid: Vec<String> = valid.iter().map(|n| format!("{n:?}")).collect();
    Err(format!(
        "no object or region of this name in scene {:?}; valid names: {}",
        scene.name,
        valid.join(", ")
    ))
}

/// The errors of an image against the reference over some pixels (NaN where undefined: a
/// region with no pixels, a ratio to a black reference).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Errors {
    pub pixels: usize,
    pub rel_mse: f64,
    pub luminance_ratio: f64,
    pub flip: f64,
}

/// An image compared with the reference: overall, per region, and FLIP's error map.
#[derive(Clone, Debug)]
pub struct Comparison {
    pub overall: Errors,
    /// In the order of [`Regions::names`].
    pub regions: Vec<Errors>,
    /// FLIP's per-pixel error, in [0, 1] (empty when none was given).
    pub flip_map: Vec<f32>,
}

/// Compares `image` with `reference` overall and over each of `regions`; `flip` is a per-pixel
/// visible-difference map in [0, 1] (FLIP's, see the module's comment), or empty, which makes
/// every `flip` field NaN.
///
/// # Panics
/// When the sizes of the images, the regions and a non-empty map differ.
pub fn compare_with_map(
    image: &RgbImage32,
    reference: &RgbImage32,
    regions: &Regions,
    flip: Vec<f32>,
) -> Comparison {
    assert_eq!(image.pixels.len(), reference.pixels.len(), "images of equal size");
    assert_eq!(image.pixels.len(), regions.of_pixel.len(), "regions of the image's size");
    assert!(flip.is_empty() || flip.len() == image.pixels.len(), "a map of the image's size");
    let errors = |pixels: &mut dyn Iterator<Item = usize>| {
        let (mut n, mut rel, mut lum_a, mut lum_r, mut flip_sum) = (0usize, 0.0, 0.0, 0.0, 0.0);
        for i in pixels {
            let (a, r) = (image.pixels[i], reference.pixels[i]);
            for c in 0..3 {
                let (a, r) = (f64::from(a[c]), f64::from(r[c]));
                rel += (a - r) * (a - r) / (r * r + REL_MSE_EPSILON);
            }
            lum_a += luminance(a);
            lum_r += luminance(r);
            flip_sum += flip.get(i).map_or(f64::NAN, |&f| f64::from(f));
            n += 1;
        }
        let per_pixel = |sum: f64| if n == 0 { f64::NAN } else { sum / n as f64 };
        Errors {
            pixels: n,
            rel_mse: per_pixel(rel / 3.0),
            luminance_ratio: if lum_r > 0.0 { lum_a / lum_r } else { f64::NAN },
            flip: per_pixel(flip_sum),
        }
    };
    let overall = errors(&mut (0..image.pixels.len()));
    let per_region = (0..regions.names.len())
        .map(|r| errors(&mut regions.of_pixel.iter().enumerate().filter(|(_, p)| **p == r).map(|(i, _)| i)))
        .collect();
    Comparison { overall, regions: per_region, flip_map: flip }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Regions are named from the scene, sorted sky first, and slivers under 0.5% of the image
    /// are merged into one.
    #[test]
    fn regions_are_named_by_what_is_seen_and_slivers_are_merged() {
        let scene = illum_scene::testing::shipped_scene("whitted.toml", 100, 10);
        let (floor, glass, metal) = (0, 1, 2);
        let mut hit = vec![None; 1000];
        let mut shadow = vec![Shadow::Lit; 1000];
        hit[..500].fill(Some(floor));
        shadow[400..500].fill(Shadow::BlockedBy(glass));
        hit[500..504].fill(Some(metal)); // 0.4%: merged
        hit[504..508].fill(Some(floor));
        shadow[504..508].fill(Shadow::FacingAway); // 0.4%: merged
        let ids = ObjectIds { width: 100, height: 10, hit, shadow };
        let regions = Regions::from_ids(&scene, &ids);
        assert_eq!(
            regions.names,
            [
                "sky",
                "floor, lit",
                "floor in the glass sphere's shadow",
                "other (regions under 0.5% of the image)"
            ]
        );
        assert_eq!(regions.sizes(), [492, 400, 100, 8]);
    }
}
