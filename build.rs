// Embeds every SPIR-V module listed in glsl/kernels.txt, so the binary runs without glslang.
// (Rebuilding spv/ from glsl/ is `make spv`; tests/spv_fresh.rs fails when spv/ is stale.)
use std::{env, fs, path::Path};

fn main() {
    let root = env::var("CARGO_MANIFEST_DIR").unwrap();
    let list = Path::new(&root).join("glsl/kernels.txt");
    println!("cargo:rerun-if-changed={}", list.display());
    let text = fs::read_to_string(&list).expect("glsl/kernels.txt");
    let mut out = String::from("pub const KERNELS: &[KernelSource] = &[\n");
    for line in text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')) {
        let mut fields = line.split_whitespace();
        let name = fields.next().unwrap();
        let source = fields.next().unwrap_or_else(|| panic!("glsl/kernels.txt: `{line}` has no source"));
        let defines: Vec<String> = fields.map(|d| format!("{d:?}")).collect();
        let spv = Path::new(&root).join("spv").join(format!("{name}.spv"));
        if !spv.exists() {
            panic!("{} is missing: run `make spv` (needs glslangValidator)", spv.display());
        }
        println!("cargo:rerun-if-changed={}", spv.display());
        out += &format!(
            "    KernelSource {{ name: {name:?}, source: {source:?}, defines: &[{}], spirv: include_bytes!({:?}) }},\n",
            defines.join(", "),
            spv.display().to_string()
        );
    }
    out += "];\n";
    fs::write(Path::new(&env::var("OUT_DIR").unwrap()).join("kernels.rs"), out).unwrap();
}
