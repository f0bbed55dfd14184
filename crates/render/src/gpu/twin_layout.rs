//! Checks a `Pod` struct against its WGSL twin from naga's own layout,
//! for the tests: the same size, and every WGSL member at the offset of
//! the Rust field of its name (fields named `_…` are padding, on either
//! side; the size covers them). Nothing is computed by hand, so a field added on
//! one side only, or moved, fails the test that names both structs.

/// Asserts the twin layout: `twin_layout!(module, Name, [field, …])`,
/// listing every Rust field but the padding. The WGSL struct has the Rust
/// struct's name (the twins' naming rule, issue 27): the macro takes one
/// name for both, so a twin named otherwise cannot be checked.
macro_rules! twin_layout {
    ($module:expr, $rust:ident, [$($field:ident),* $(,)?]) => {
        $crate::gpu::twin_layout::check(
            $module,
            stringify!($rust),
            std::mem::size_of::<$rust>(),
            &[$((stringify!($field), std::mem::offset_of!($rust, $field))),*],
        )
    };
}
pub(crate) use twin_layout;

/// The body of [`twin_layout!`].
pub(crate) fn check(module: &naga::Module, name: &str, rust_size: usize, fields: &[(&str, usize)]) {
    let (_, ty) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no WGSL struct {name} (the Rust struct's twin)"));
    let naga::TypeInner::Struct { members, span } = &ty.inner else {
        panic!("WGSL {name} is not a struct");
    };
    assert_eq!(*span as usize, rust_size, "size of {name} in WGSL and Rust");
    let wgsl_fields: Vec<(&str, usize)> = members
        .iter()
        .map(|m| (m.name.as_deref().unwrap_or("?"), m.offset as usize))
        .filter(|(name, _)| !name.starts_with('_'))
        .collect();
    assert_eq!(
        wgsl_fields, fields,
        "fields and offsets of {name} in WGSL against Rust"
    );
}

/// `program` assembled with `features` and generated `code`, parsed.
pub(crate) fn module_of(
    program: crate::gpu::shader_source::Program,
    features: &crate::gpu::FeatureSet,
    code: &str,
) -> naga::Module {
    let source = crate::gpu::shader_source::assemble(program, features, code).unwrap();
    naga::front::wgsl::parse_str(&source).unwrap()
}
