//! The SPIR-V kernels, embedded at build time from `spv/` as listed in `glsl/kernels.txt`.

/// One compiled kernel: its GLSL source (under `glsl/`), the preprocessor defines it was compiled with, and
/// the SPIR-V that glslang produced.
#[derive(Debug)]
pub struct KernelSource {
    pub name: &'static str,
    pub source: &'static str,
    pub defines: &'static [&'static str],
    pub spirv: &'static [u8],
}

include!(concat!(env!("OUT_DIR"), "/kernels.rs"));

/// The kernel named `name` (a name from `glsl/kernels.txt`).
pub fn kernel(name: &str) -> &'static KernelSource {
    KERNELS
        .iter()
        .find(|k| k.name == name)
        .unwrap_or_else(|| panic!("no kernel {name} in glsl/kernels.txt"))
}

impl KernelSource {
    /// The SPIR-V as words (the embedded bytes carry no alignment guarantee).
    pub fn words(&self) -> Vec<u32> {
        ash::util::read_spv(&mut std::io::Cursor::new(self.spirv)).expect("embedded SPIR-V is well formed")
    }
}
