//! WGSL composition and validation.
//!
//! Shaders live in the workspace's `shaders/` folder and are embedded at compile time. Shared
//! modules declare `#define_import_path illum::NAME` and are pulled in with `#import` by the
//! naga_oil composer; `#ifdef` shader defs select code per pipeline. The result is a validated
//! `naga::Module` handed to wgpu directly, so wgpu never re-parses WGSL.

use std::borrow::Cow;
use std::collections::HashMap;

use naga_oil::compose::{
    ComposableModuleDescriptor, Composer, NagaModuleDescriptor, ShaderDefValue, ShaderLanguage, ShaderType,
};

use crate::{GpuContext, GpuError};

/// One WGSL file: its path relative to the workspace (for error messages) and its text. Files
/// from `shaders/` are embedded ([`shader_file!`]); generated modules own their text.
#[derive(Clone, Debug)]
pub struct ShaderFile {
    pub path: Cow<'static, str>,
    pub source: Cow<'static, str>,
}

impl ShaderFile {
    /// A module generated at run time; `name` stands in for a path in error messages.
    pub fn generated(name: String, source: String) -> Self {
        Self { path: Cow::Owned(name), source: Cow::Owned(source) }
    }
}

/// Embeds `shaders/...` (a path relative to the workspace root) as a [`ShaderFile`].
#[macro_export]
macro_rules! shader_file {
    ($path:literal) => {
        $crate::shader::ShaderFile {
            path: ::std::borrow::Cow::Borrowed($path),
            source: ::std::borrow::Cow::Borrowed(include_str!(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../../",
                $path
            ))),
        }
    };
}

/// Shared modules, in dependency order (a module may import only those before it).
pub const COMMON_MODULES: &[ShaderFile] = &[
    crate::shader_file!("shaders/common/constants.wgsl"),
    crate::shader_file!("shaders/common/rng.wgsl"),
    crate::shader_file!("shaders/common/sampling.wgsl"),
    crate::shader_file!("shaders/common/sampler.wgsl"),
    crate::shader_file!("shaders/common/spawn.wgsl"),
];

/// A shader def: `#ifdef NAME` / `#if NAME == value` in WGSL.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Def {
    Bool(bool),
    UInt(u32),
}

/// Composes `entry` with `modules` into one validated naga module.
pub fn compose(
    modules: &[ShaderFile],
    entry: &ShaderFile,
    defs: &[(&str, Def)],
) -> Result<naga::Module, GpuError> {
    let shader_defs: HashMap<String, ShaderDefValue> = defs
        .iter()
        .map(|(name, value)| {
            let value = match value {
                Def::Bool(b) => ShaderDefValue::Bool(*b),
                Def::UInt(u) => ShaderDefValue::UInt(*u),
            };
            ((*name).to_owned(), value)
        })
        .collect();
    let mut composer = Composer::default();
    for module in modules {
        let added = composer
            .add_composable_module(ComposableModuleDescriptor {
                source: &module.source,
                file_path: &module.path,
                language: ShaderLanguage::Wgsl,
                shader_defs: shader_defs.clone(),
                ..Default::default()
            })
            .map(|_| ());
        added.map_err(|e| GpuError::Shader {
            file: module.path.to_string(),
            message: e.emit_to_string(&composer),
        })?;
    }
    composer
        .make_naga_module(NagaModuleDescriptor {
            source: &entry.source,
            file_path: &entry.path,
            shader_type: ShaderType::Wgsl,
            shader_defs,
            ..Default::default()
        })
        .map_err(|e| GpuError::Shader { file: entry.path.to_string(), message: e.emit_to_string(&composer) })
}

/// Validates a composed module with naga's validator (all capabilities wgpu's core needs).
pub fn validate(module: &naga::Module, file: &str) -> Result<naga::valid::ModuleInfo, GpuError> {
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
        .validate(module)
        .map_err(|e| GpuError::Shader { file: file.to_owned(), message: format!("{e:?}") })
}

/// Creates a wgpu shader module from a composed naga module, reporting validation errors.
pub fn create_module(
    gpu: &GpuContext,
    module: naga::Module,
    label: &str,
) -> Result<wgpu::ShaderModule, GpuError> {
    gpu.scoped(label, || {
        gpu.device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Naga(Cow::Owned(module)),
        })
    })
}

/// Composes `entry` with `modules` under `defs` and builds a compute pipeline of its `main`
/// entry point, with the bind group layout derived from the shader. Composition, validation and
/// out-of-memory errors come back as [`GpuError`]s that name `label`.
pub fn compute_pipeline(
    gpu: &GpuContext,
    modules: &[ShaderFile],
    entry: &ShaderFile,
    defs: &[(&str, Def)],
    label: &str,
) -> Result<wgpu::ComputePipeline, GpuError> {
    let module = create_module(gpu, compose(modules, entry, defs)?, &entry.path)?;
    gpu.scoped(&format!("creating the {label} pipeline"), || {
        gpu.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        })
    })
}
