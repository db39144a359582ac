// Embeds every SPIR-V module listed in glsl/kernels.txt, so the binary runs without glslang, and the GLSL
// sources themselves, from which `.brdf` models' kernels are composed at run time.
// (Rebuilding spv/ from glsl/ is `make spv`; tests/kernels/sources.rs fails when spv/ is stale.)
use std::{env, fs, path::Path};

fn main() {
    let root = env::var("CARGO_MANIFEST_DIR").unwrap();
    let glsl = Path::new(&root).join("glsl");
    let list = glsl.join("kernels.txt");
    println!("cargo:rerun-if-changed={}", list.display());
    let text = fs::read_to_string(&list).expect("glsl/kernels.txt");
    let mut out = String::from("pub const KERNELS: &[KernelSource] = &[\n");
    for line in text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')) {
        let mut fields = line.split_whitespace();
        let name = fields.next().unwrap();
        let source = fields.next().unwrap_or_else(|| panic!("glsl/kernels.txt: `{line}` has no source"));
        let defines: Vec<String> = fields.map(|d| format!("{d:?}")).collect();
        let spv = Path::new(&root).join("spv").join(format!("{name}.spv"));
        println!("cargo:rerun-if-changed={}", spv.display());
        // A missing module (a kernel just added to kernels.txt) embeds as empty, so that the binary still builds
        // and `make spv` can run it to regenerate glsl/generated/ first; using the kernel then says so.
        let bytes = if spv.exists() {
            format!("include_bytes!({:?})", spv.display().to_string())
        } else {
            println!("cargo:warning={} is missing: run `make spv` (needs glslangValidator)", spv.display());
            "&[]".to_string()
        };
        out += &format!(
            "    KernelSource {{ name: {name:?}, source: {source:?}, defines: &[{}], spirv: {bytes} }},\n",
            defines.join(", ")
        );
    }
    out += "];\n\n/// Every file under glsl/ (relative path, text).\npub const GLSL_FILES: &[(&str, &str)] = &[\n";
    let mut files = Vec::new();
    collect(&glsl, &glsl, &mut files);
    files.sort();
    for (rel, path) in files {
        println!("cargo:rerun-if-changed={path}");
        out += &format!("    ({rel:?}, include_str!({path:?})),\n");
    }
    out += "];\n";
    fs::write(Path::new(&env::var("OUT_DIR").unwrap()).join("kernels.rs"), out).unwrap();
}

fn collect(root: &Path, dir: &Path, out: &mut Vec<(String, String)>) {
    println!("cargo:rerun-if-changed={}", dir.display());
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            collect(root, &path, out);
        } else if path.extension().is_some_and(|e| e == "glsl" || e == "comp" || e == "txt") {
            let rel = path.strip_prefix(root).unwrap().to_string_lossy().replace('\\', "/");
            out.push((rel, path.display().to_string()));
        }
    }
}
