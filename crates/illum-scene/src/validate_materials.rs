//! Validation of the `[materials]` tables: exactly one kind per material, each kind's numbers in
//! its range. Same rules as `validate.rs`: every number is checked for finiteness in f32 before
//! it is compared.

use std::collections::BTreeMap;

use glam::Vec3;

use crate::error::SceneError;
use crate::file::RawMaterial;
use crate::materials::{Checker, Material, MaterialKind};
use crate::spelling::{fmt_num, fmt_vec, toml_key};
use crate::validate::Check;

impl Check<'_> {
    /// Materials in sorted-name order, plus the name -> index map objects resolve against.
    pub(crate) fn materials(
        &self,
        raw: &BTreeMap<String, RawMaterial>,
    ) -> Result<(Vec<Material>, BTreeMap<String, usize>), SceneError> {
        let mut materials = Vec::with_capacity(raw.len());
        let mut index_of = BTreeMap::new();
        for (name, m) in raw {
            let path = format!("materials.{}", toml_key(name));
            index_of.insert(name.clone(), materials.len());
            materials.push(Material { name: name.clone(), kind: self.material_kind(&path, m)? });
        }
        Ok((materials, index_of))
    }

    fn material_kind(&self, path: &str, m: &RawMaterial) -> Result<MaterialKind, SceneError> {
        let given: Vec<&str> = [
            (m.albedo.is_some(), "albedo"),
            (m.checker.is_some(), "checker"),
            (m.dielectric.is_some(), "dielectric"),
            (m.mirror.is_some(), "mirror"),
            (m.emission.is_some(), "emission"),
        ]
        .into_iter()
        .filter_map(|(present, key)| present.then_some(key))
        .collect();
        if given.len() != 1 {
            let value =
                if given.is_empty() { "{}".to_owned() } else { format!("{{ {} }}", given.join(", ")) };
            return Err(self.invalid(
                path,
                value,
                "a material needs exactly one of albedo (Lambertian), checker (Lambertian \
                 checkerboard), dielectric (glass), mirror, emission (area light)",
            ));
        }
        if let Some(albedo) = m.albedo {
            return Ok(MaterialKind::Lambertian {
                albedo: self.reflectance(&format!("{path}.albedo"), albedo)?,
            });
        }
        if let Some(c) = &m.checker {
            return Ok(MaterialKind::Checker(Checker {
                even: self.reflectance(&format!("{path}.checker.even"), c.even)?,
                odd: self.reflectance(&format!("{path}.checker.odd"), c.odd)?,
                tile: self.positive(&format!("{path}.checker.tile"), c.tile)?,
            }));
        }
        if let Some(d) = &m.dielectric {
            let field = format!("{path}.dielectric.ior");
            let ior = self.number(&field, d.ior)?;
            if ior <= 0.0 {
                return Err(self.invalid(
                    field,
                    fmt_num(d.ior.0),
                    "must be > 0 (the index of refraction inside; outside is 1, so 1 makes the \
                     surface vanish and 1.43 is glass)",
                ));
            }
            return Ok(MaterialKind::Dielectric { ior });
        }
        if let Some(mirror) = &m.mirror {
            let reflectance = self.reflectance(&format!("{path}.mirror.reflectance"), mirror.reflectance)?;
            return Ok(MaterialKind::Mirror { reflectance });
        }
        let raw = m.emission.expect("exactly one key is present");
        let field = format!("{path}.emission");
        let radiance = self.vec3(&field, raw)?;
        if !(radiance.cmpge(Vec3::ZERO).all() && radiance.max_element() > 0.0) {
            return Err(self.invalid(
                field,
                fmt_vec(raw.0),
                "every channel must be >= 0 and one > 0 (emitted radiance; for a black surface \
                 write albedo = [0, 0, 0])",
            ));
        }
        Ok(MaterialKind::Emitter { radiance })
    }
}
