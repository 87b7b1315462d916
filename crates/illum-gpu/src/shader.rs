//! WGSL composition and validation.
//!
//! Each crate keeps its shaders in its own `shaders/` folder, embedded at compile time. Shared
//! modules declare `#define_import_path illum::NAME` and are pulled in with `#import` by the
//! naga_oil composer; `#ifdef` shader defs select code per pipeline. The result is a validated
//! `naga::Module` handed to wgpu directly, so wgpu never re-parses WGSL.

use std::borrow::Cow;
use std::collections::HashMap;

use naga_oil::compose::{
    ComposableModuleDescriptor, Composer, NagaModuleDescriptor, ShaderDefValue, ShaderLanguage, ShaderType,
};

use crate::{GpuContext, GpuError};

/// One WGSL file: its path relative to the workspace (for error messages) and its text. A
/// crate's `shaders/` files are embedded (`shader_file!`); generated modules own their text.
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

/// Embeds `shaders/...` of the calling crate (a path relative to its manifest) as a
/// [`ShaderFile`] named `crates/<crate>/shaders/...`, its path in the workspace.
#[macro_export]
macro_rules! shader_file {
    ($path:literal) => {
        $crate::shader::ShaderFile {
            path: ::std::borrow::Cow::Borrowed(concat!("crates/", env!("CARGO_PKG_NAME"), "/", $path)),
            source: ::std::borrow::Cow::Borrowed(include_str!(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/",
                $path
            ))),
        }
    };
}

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

/// The shader defs `#ifdef NAME` for the flags that are on, in the given order.
pub fn flag_defs(flags: &[(&'static str, bool)]) -> Vec<(&'static str, Def)> {
    flags.iter().filter(|&&(_, on)| on).map(|&(name, _)| (name, Def::Bool(true))).collect()
}

/// Validates a composed module with naga's validator (all capabilities wgpu's core needs).
pub fn validate(module: &naga::Module, file: &str) -> Result<naga::valid::ModuleInfo, GpuError> {
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
        .validate(module)
        .map_err(|e| GpuError::Shader { file: file.to_owned(), message: format!("{e:?}") })
}

/// Composes and validates each of `modules` on its own, as the import of a trivial entry point
/// with the modules before it (a module may import only those): a module no entry point uses
/// yet is still checked.
pub fn validate_each_module(modules: &[ShaderFile]) -> Result<(), GpuError> {
    for (i, module) in modules.iter().enumerate() {
        let import_path = module
            .source
            .lines()
            .find_map(|l| l.strip_prefix("#define_import_path "))
            .ok_or_else(|| GpuError::Shader {
                file: module.path.to_string(),
                message: "no #define_import_path line".to_owned(),
            })?
            .trim();
        let entry = ShaderFile::generated(
            format!("entry importing {import_path}"),
            format!("#import {import_path} as m\n@compute @workgroup_size(1)\nfn main() {{}}\n"),
        );
        validate(&compose(&modules[..=i], &entry, &[])?, &entry.path)?;
    }
    Ok(())
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

/// What a compute pipeline was built from: every module's and the entry file's text, and the
/// shader defs. Equal keys give the same pipeline.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(crate) struct ComputePipelineKey {
    sources: Vec<String>,
    defs: Vec<(String, Def)>,
}

/// Composes `entry` with `modules` under `defs` and builds a compute pipeline of its `main`
/// entry point, with the bind group layout derived from the shader. Composition, validation and
/// out-of-memory errors come back as [`GpuError`]s that name `label`.
///
/// Pipelines are cached in `gpu` (and shared by its clones) by the text they are built from, so
/// building the same one again, for example for a scene with the same specialisation, does not
/// compile it again. The cache dies with the context.
pub fn compute_pipeline(
    gpu: &GpuContext,
    modules: &[ShaderFile],
    entry: &ShaderFile,
    defs: &[(&str, Def)],
    label: &str,
) -> Result<wgpu::ComputePipeline, GpuError> {
    let key = ComputePipelineKey {
        sources: modules.iter().chain([entry]).map(|m| m.source.to_string()).collect(),
        defs: defs.iter().map(|(name, value)| ((*name).to_owned(), *value)).collect(),
    };
    let cache = || gpu.compute_pipelines.lock().unwrap_or_else(|p| p.into_inner());
    if let Some(pipeline) = cache().get(&key) {
        return Ok(pipeline.clone());
    }
    let module = create_module(gpu, compose(modules, entry, defs)?, &entry.path)?;
    let pipeline = gpu.scoped(&format!("creating the {label} pipeline"), || {
        gpu.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        })
    })?;
    cache().insert(key, pipeline.clone());
    Ok(pipeline)
}

/// The `(name, byte offset)` of each listed field of a Rust struct, for
/// [`WgslStruct::assert_matches`]: `members!(GpuParams: eye, tan_half_fov, ...)`.
#[macro_export]
macro_rules! members {
    ($ty:ty: $($field:ident),* $(,)?) => {
        [$((stringify!($field), ::std::mem::offset_of!($ty, $field))),*]
    };
}

/// A WGSL struct as naga lays it out: its size and each member's byte offset.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WgslStruct {
    pub name: String,
    pub size: u32,
    pub members: Vec<(String, u32)>,
}

impl WgslStruct {
    /// Asserts that a Rust mirror of `size` bytes has exactly these members at these offsets
    /// (use `size_of` and `offset_of!` on the Rust struct), naming the first difference.
    ///
    /// # Panics
    /// When the size, the member names or any offset differ.
    pub fn assert_matches(&self, size: usize, members: &[(&str, usize)]) {
        assert_eq!(size, self.size as usize, "size of the Rust mirror of WGSL struct {}", self.name);
        let wgsl: Vec<(&str, usize)> = self.members.iter().map(|(n, o)| (n.as_str(), *o as usize)).collect();
        assert_eq!(
            members,
            wgsl.as_slice(),
            "members (name, offset) of the Rust mirror of WGSL struct {}",
            self.name
        );
    }
}

/// The layout of struct `name` of module `import_path` (as it declares with
/// `#define_import_path`) in a composed `module`, or `None` when the module does not contain it.
pub fn wgsl_struct(module: &naga::Module, import_path: &str, name: &str) -> Option<WgslStruct> {
    let decorated = Composer::decorated_name(Some(import_path), name);
    module.types.iter().find_map(|(_, ty)| match &ty.inner {
        naga::TypeInner::Struct { members, span }
            if ty.name.as_deref().is_some_and(|n| n == name || n == decorated) =>
        {
            Some(WgslStruct {
                name: name.to_owned(),
                size: *span,
                members: members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset)).collect(),
            })
        }
        _ => None,
    })
}
