//! Throwaway (marbre issue 19 item 6): marbre's #if preprocessor vs naga_oil vs wesl.
#[allow(dead_code)]
#[path = "/work/h6/src/gpu/preprocess.rs"]
mod preprocess;
use std::collections::{BTreeSet, HashMap};
use std::time::Instant;

const SH: &str = "/work/h6/shaders";
fn read(name: &str) -> String { std::fs::read_to_string(format!("{SH}/{name}")).unwrap() }

fn naga_validate(src: &str) -> Result<(), String> {
    let m = naga::front::wgsl::parse_str(src).map_err(|e| e.emit_to_string(src))?;
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .validate(&m).map_err(|e| e.emit_to_string(src))?;
    Ok(())
}

/// `#if A` -> `#ifdef A`; `#if A || B` -> `#ifdef A__OR__B` (a derived def).
fn to_naga_oil(text: &str, derived: &mut BTreeSet<String>) -> String {
    text.lines().map(|l| {
        let t = l.trim();
        if let Some(c) = t.strip_prefix("#if ") {
            if c.contains("||") {
                let name = c.split("||").map(|s| s.trim()).collect::<Vec<_>>().join("__OR__");
                derived.insert(name.clone());
                format!("#ifdef {name}")
            } else if let Some(n) = c.strip_prefix('!') { format!("#ifndef {}", n.trim()) }
            else { format!("#ifdef {c}") }
        } else { l.to_owned() }
    }).collect::<Vec<_>>().join("\n") + "\n"
}

fn main() {
    let data = "/work/h6-pp/data";
    let files: Vec<String> = std::fs::read_to_string(format!("{data}/files.txt")).unwrap().lines().map(String::from).collect();
    let defines_s = std::fs::read_to_string(format!("{data}/defines.txt")).unwrap();
    let defines: BTreeSet<&str> = defines_s.lines().collect();
    let generated = std::fs::read_to_string(format!("{data}/generated.wgsl")).unwrap();
    let shader_files: Vec<&String> = files.iter().filter(|f| f.ends_with(".wgsl")).collect();
    let texts: Vec<(String, String)> = shader_files.iter().map(|f| (f.to_string(), read(f))).collect();

    // ---- marbre: preprocess + concatenate + naga parse/validate
    let ours = || {
        let mut m = String::new();
        for (name, t) in &texts {
            m.push_str(&format!("// ---- {name}\n"));
            m.push_str(&preprocess::preprocess(t, name, &defines).unwrap());
        }
        m.push_str("// ---- generated textures\n");
        m.push_str(&generated);
        m
    };
    let module = ours();
    assert_eq!(module, std::fs::read_to_string(format!("{data}/module.wgsl")).unwrap(), "replica differs");
    naga_validate(&module).unwrap();

    // ---- naga_oil, one module (no #import): converted directives, defs
    let mut derived = BTreeSet::new();
    let mut oil_src = String::new();
    for (name, t) in &texts { oil_src.push_str(&format!("// ---- {name}\n")); oil_src.push_str(&to_naga_oil(t, &mut derived)); }
    oil_src.push_str("// ---- generated textures\n"); oil_src.push_str(&generated);
    let mut defs: HashMap<String, naga_oil::compose::ShaderDefValue> = defines.iter().map(|d| (d.to_string(), naga_oil::compose::ShaderDefValue::Bool(true))).collect();
    for d in &derived { if d.split("__OR__").any(|x| defines.contains(x)) { defs.insert(d.clone(), naga_oil::compose::ShaderDefValue::Bool(true)); } }
    let mut composer = naga_oil::compose::Composer::default().with_capabilities(naga::valid::Capabilities::all());
    let oil = |composer: &mut naga_oil::compose::Composer| composer.make_naga_module(naga_oil::compose::NagaModuleDescriptor {
        source: &oil_src, file_path: "trace.wgsl", shader_defs: defs.clone(), ..Default::default() });
    match oil(&mut composer) { Ok(_) => println!("naga_oil: uber trace shader (one module, {} derived defs) composes and validates", derived.len()), Err(e) => println!("naga_oil error:\n{}", e.emit_to_string(&composer)) }

    // ---- wesl on the already-filtered module (lower bound: parse + condcomp + print)
    let wesl_run = |src: &str| -> Result<String, String> {
        let mut r = wesl::VirtualResolver::new();
        let src = src.replace("(u < 0.0 | v < 0.0 | w < 0.0) & (u > 0.0 | v > 0.0 | w > 0.0)", "((u < 0.0) | (v < 0.0) | (w < 0.0)) & ((u > 0.0) | (v > 0.0) | (w > 0.0))");
        let src = src.replace("let hit = !mixed & det != 0.0 & t > 0.0 & t < t_max;", "let hit = (!mixed) & (det != 0.0) & (t > 0.0) & (t < t_max);");
        r.add_module("package::main".parse().unwrap(), src.into());
        let mut w = wesl::Wesl::new_barebones().set_custom_resolver(r);
        w.use_condcomp(true);
        w.compile(&"package::main".parse().unwrap()).map(|c| c.to_string()).map_err(|e| e.to_string())
    };
    match wesl_run(&module) { Ok(out) => { println!("wesl: uber module passes through, {} -> {} lines", module.lines().count(), out.lines().count()); if let Err(e) = naga_validate(&out) { println!("  but naga rejects wesl output: {}", &e[..e.len().min(600)]) } }
        Err(e) => println!("wesl error on our module:\n{}", &e[..e.len().min(1500)]) }

    // ---- timing, interleaved
    let n = 20;
    for round in 0..3 {
        let t = Instant::now(); for _ in 0..n { naga_validate(&ours()).unwrap(); } let a = t.elapsed().as_secs_f64()*1e3/n as f64;
        let t = Instant::now(); for _ in 0..n { let _ = std::hint::black_box(oil(&mut composer)); } let b = t.elapsed().as_secs_f64()*1e3/n as f64;
        let t = Instant::now(); for _ in 0..n { let mut c = naga_oil::compose::Composer::default().with_capabilities(naga::valid::Capabilities::all()); let _ = std::hint::black_box(oil(&mut c)); } let b2 = t.elapsed().as_secs_f64()*1e3/n as f64;
        let t = Instant::now(); for _ in 0..n { let o = wesl_run(&ours()); if let Ok(o) = o { let _ = naga_validate(&o); } else { print!("(wesl failed) "); break; } } let c = t.elapsed().as_secs_f64()*1e3/n as f64;
        let t = Instant::now(); for _ in 0..200 { std::hint::black_box(ours()); } let p = t.elapsed().as_secs_f64()*1e3/200.0;
        println!("round {round}: marbre pp+naga {a:.2} ms (pp alone {p:.3}); naga_oil make_naga_module {b:.2} ms (fresh Composer {b2:.2}); marbre pp + wesl pass + naga {c:.2} ms");
    }
    demos();
}

fn demos() {
    use naga_oil::compose::*;
    let hash = read("hash.wgsl"); let ng = read("noise_gradient.wgsl");
    let mut d = BTreeSet::new();
    let hash_oil = format!("#define_import_path marbre::hash\n{}", to_naga_oil(&hash, &mut d));
    let ng_oil = |bad: bool| format!("#define_import_path marbre::noise_gradient\n#import marbre::hash::gradient_pcg\n#ifdef HASH_SIN\n#import marbre::hash::gradient_sin\n#endif\n{}", to_naga_oil(&ng, &mut BTreeSet::new()).replacen("    let f = p - i;", if bad { "    let f = p - i + 1u;" } else { "    let f = p - i;" }, 1));
    let root = "#import marbre::noise_gradient::gradient_noise\n@group(0) @binding(0) var<storage, read_write> out: array<f32>;\n@compute @workgroup_size(64)\nfn main(@builtin(global_invocation_id) id: vec3u) {\n    out[id.x] = gradient_noise(vec3f(f32(id.x)), 1u);\n}\n";
    for (hs, bad) in [(true, false), (false, false), (true, true)] {
        let mut defs = HashMap::new(); if hs { defs.insert("HASH_SIN".to_string(), ShaderDefValue::Bool(true)); }
        let mut c = Composer::default();
        let r = (|| -> Result<naga::Module, ComposerError> {
            c.add_composable_module(ComposableModuleDescriptor { source: &hash_oil, file_path: "shaders/hash.wgsl", shader_defs: defs.clone(), ..Default::default() })?;
            let s = ng_oil(bad);
            c.add_composable_module(ComposableModuleDescriptor { source: &s, file_path: "shaders/noise_gradient.wgsl", shader_defs: defs.clone(), ..Default::default() })?;
            c.make_naga_module(NagaModuleDescriptor { source: root, file_path: "root.wgsl", shader_defs: defs.clone(), ..Default::default() })
        })();
        match r { Ok(m) => println!("naga_oil imports demo HASH_SIN={hs}: ok, {} functions", m.functions.len()),
                  Err(e) => println!("naga_oil imports demo HASH_SIN={hs} bad={bad}: error:\n{}", e.emit_to_string(&c)) }
    }
    // wesl: @if attributes + imports
    let hash_w = hash.replace("#if HASH_SIN\n", "@if(HASH_SIN)\n").replace("#endif\n", "");
    let ng_w = |bad: bool| format!("import package::hash::{{gradient_pcg, gradient_sin}};\n{}", ng.replace("#if HASH_SIN\n    if hash", "    @if(HASH_SIN) if hash").replace("#endif\n", "").replacen("    let f = p - i;", if bad { "    let f = p - i + 1u;" } else { "    let f = p - i;" }, 1));
    let root_w = "import package::noise_gradient::gradient_noise;\n@group(0) @binding(0) var<storage, read_write> out: array<f32>;\n@compute @workgroup_size(64)\nfn main(@builtin(global_invocation_id) id: vec3u) {\n    out[id.x] = gradient_noise(vec3f(f32(id.x)), 1u);\n}\n";
    for (hs, bad) in [(true, false), (false, false), (true, true)] {
        let mut r = wesl::VirtualResolver::new();
        r.add_module("package::hash".parse().unwrap(), hash_w.clone().into());
        r.add_module("package::noise_gradient".parse().unwrap(), ng_w(bad).into());
        r.add_module("package::main".parse().unwrap(), root_w.into());
        let mut w = wesl::Wesl::new("shaders").set_custom_resolver(r);
        w.set_feature("HASH_SIN", hs); w.use_sourcemap(true);
        match w.compile(&"package::main".parse().unwrap()) {
            Ok(out) => { let s = out.to_string(); println!("wesl demo HASH_SIN={hs} bad={bad}: ok, {} lines; naga: {}", s.lines().count(), match naga_validate(&s) { Ok(()) => "valid".into(), Err(e) => format!("\n{e}") }); if !bad && hs { println!("{s}"); } }
            Err(e) => println!("wesl demo HASH_SIN={hs} bad={bad} error: {e}"),
        }
    }
}
