//! NVIDIA's runtime compiler (NVRTC, `libnvrtc.so.13` from the `nvidia-cuda-nvrtc` wheel), loaded at run time:
//! CUDA C++ to a cubin for one compute capability, with ptxas' resource report in its log, and nvdisasm's
//! SASS listing of the cubin. No NVIDIA GPU or driver is involved.

use anyhow::{anyhow, bail, Context, Result};
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

type Program = *mut c_void;
type NvrtcResult = c_int;

/// The NVRTC C API (nvrtc.h) brdfprof calls.
struct Api {
    create: unsafe extern "C" fn(*mut Program, *const c_char, *const c_char, c_int, *const *const c_char, *const *const c_char) -> NvrtcResult,
    compile: unsafe extern "C" fn(Program, c_int, *const *const c_char) -> NvrtcResult,
    log_size: unsafe extern "C" fn(Program, *mut usize) -> NvrtcResult,
    log: unsafe extern "C" fn(Program, *mut c_char) -> NvrtcResult,
    cubin_size: unsafe extern "C" fn(Program, *mut usize) -> NvrtcResult,
    cubin: unsafe extern "C" fn(Program, *mut c_char) -> NvrtcResult,
    destroy: unsafe extern "C" fn(*mut Program) -> NvrtcResult,
    error_string: unsafe extern "C" fn(NvrtcResult) -> *const c_char,
}

/// NVRTC and nvdisasm, found under the install directory.
pub struct Tools {
    _lib: libloading::Library,
    api: Api,
    pub nvdisasm: PathBuf,
    /// "NVRTC 13.5".
    pub version: String,
    /// nvdisasm's `--version` line with its build.
    pub nvdisasm_version: String,
}

/// The pinned wheel versions `make setup` installs (scripts/setup.sh reads the same line of the Makefile).
pub const WHEELS: &str = "nvidia-cuda-nvrtc==13.5.37 nvidia-cuda-nvdisasm==13.5.37";

/// Where `make setup` installs the wheels: `$BRDFPROF_NVIDIA_DIR`, else `.tools/nvidia` in the checkout
/// brdfprof was built from.
pub fn install_dir() -> PathBuf {
    match std::env::var_os("BRDFPROF_NVIDIA_DIR").filter(|d| !d.is_empty()) {
        Some(d) => PathBuf::from(d),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join(".tools/nvidia"),
    }
}

fn not_installed(why: &str) -> String {
    format!(
        "NVIDIA compiler not installed: run `make setup` (it installs NVIDIA's NVRTC and nvdisasm wheels, {WHEELS}, into {}; about 150 MB); {why}",
        install_dir().display()
    )
}

fn load() -> std::result::Result<Tools, String> {
    let base = install_dir().join("nvidia/cu13");
    let lib_path = base.join("lib/libnvrtc.so.13");
    let nvdisasm = base.join("bin/nvdisasm");
    if !lib_path.is_file() || !nvdisasm.is_file() {
        return Err(not_installed(&format!("{} or {} is missing", lib_path.display(), nvdisasm.display())));
    }
    // SAFETY: NVRTC's library, loaded for its documented C API; its initialisers are NVIDIA's.
    let lib = unsafe { libloading::Library::new(&lib_path) }.map_err(|e| not_installed(&format!("cannot load {}: {e}", lib_path.display())))?;
    // SAFETY: each symbol is looked up with the signature nvrtc.h gives it.
    let api = unsafe {
        let sym = |name: &[u8]| -> std::result::Result<*const c_void, String> {
            lib.get::<*const c_void>(name).map(|s| *s).map_err(|e| not_installed(&format!("{}: {e}", String::from_utf8_lossy(&name[..name.len() - 1]))))
        };
        Api {
            create: std::mem::transmute::<*const c_void, _>(sym(b"nvrtcCreateProgram\0")?),
            compile: std::mem::transmute::<*const c_void, _>(sym(b"nvrtcCompileProgram\0")?),
            log_size: std::mem::transmute::<*const c_void, _>(sym(b"nvrtcGetProgramLogSize\0")?),
            log: std::mem::transmute::<*const c_void, _>(sym(b"nvrtcGetProgramLog\0")?),
            cubin_size: std::mem::transmute::<*const c_void, _>(sym(b"nvrtcGetCUBINSize\0")?),
            cubin: std::mem::transmute::<*const c_void, _>(sym(b"nvrtcGetCUBIN\0")?),
            destroy: std::mem::transmute::<*const c_void, _>(sym(b"nvrtcDestroyProgram\0")?),
            error_string: std::mem::transmute::<*const c_void, _>(sym(b"nvrtcGetErrorString\0")?),
        }
    };
    // SAFETY: nvrtcVersion(int*, int*), as nvrtc.h declares it.
    let version = unsafe {
        let f: libloading::Symbol<unsafe extern "C" fn(*mut c_int, *mut c_int) -> NvrtcResult> = lib.get(b"nvrtcVersion\0").map_err(|e| not_installed(&e.to_string()))?;
        let (mut major, mut minor) = (0, 0);
        f(&mut major, &mut minor);
        format!("NVRTC {major}.{minor}")
    };
    // Its last line names the build ("Build cuda_13.5.r13.5/compiler.37..."): the cache keys on it.
    let nvdisasm_version = std::process::Command::new(&nvdisasm).arg("--version").output().ok().and_then(|o| String::from_utf8_lossy(&o.stdout).lines().last().map(str::to_string)).unwrap_or_default();
    Ok(Tools { _lib: lib, api, nvdisasm, version, nvdisasm_version })
}

/// The tools, loaded once per process; an error naming the fix when they are not installed.
pub fn tools() -> Result<&'static Tools> {
    static TOOLS: OnceLock<std::result::Result<Tools, String>> = OnceLock::new();
    TOOLS.get_or_init(load).as_ref().map_err(|e| anyhow!("{e}"))
}

/// What one compilation produced.
pub struct Compiled {
    pub cubin: Vec<u8>,
    /// NVRTC's log with ptxas' `-v` resource report.
    pub log: String,
}

impl Tools {
    fn error(&self, code: NvrtcResult) -> String {
        // SAFETY: nvrtcGetErrorString returns a static string for any code.
        unsafe { CStr::from_ptr((self.api.error_string)(code)).to_string_lossy().into_owned() }
    }

    /// Compiles `source` with `options` (each `-arch=sm_XX`, ...) to a cubin.
    pub fn compile(&self, source: &str, name: &str, options: &[String]) -> Result<Compiled> {
        let src = CString::new(source).context("the CUDA source holds a NUL byte")?;
        let cname = CString::new(name).context("a kernel name with a NUL byte")?;
        let opts: Vec<CString> = options.iter().map(|o| CString::new(o.as_str())).collect::<Result<_, _>>().context("an NVRTC option with a NUL byte")?;
        let ptrs: Vec<*const c_char> = opts.iter().map(|o| o.as_ptr()).collect();
        let mut prog: Program = std::ptr::null_mut();
        // SAFETY: the NVRTC API as documented: a program created from NUL-terminated strings, compiled,
        // queried for its log and cubin into buffers of the sizes it reports, destroyed once.
        unsafe {
            let r = (self.api.create)(&mut prog, src.as_ptr(), cname.as_ptr(), 0, std::ptr::null(), std::ptr::null());
            if r != 0 {
                bail!("nvrtcCreateProgram: {}", self.error(r));
            }
            let compiled = (self.api.compile)(prog, ptrs.len() as c_int, ptrs.as_ptr());
            let mut size = 0usize;
            (self.api.log_size)(prog, &mut size);
            let mut log = vec![0u8; size.max(1)];
            (self.api.log)(prog, log.as_mut_ptr() as *mut c_char);
            let log = String::from_utf8_lossy(&log).trim_end_matches('\0').to_string();
            let mut cubin = Vec::new();
            if compiled == 0 {
                (self.api.cubin_size)(prog, &mut size);
                cubin = vec![0u8; size];
                (self.api.cubin)(prog, cubin.as_mut_ptr() as *mut c_char);
            }
            (self.api.destroy)(&mut prog);
            if compiled != 0 {
                bail!("NVRTC cannot compile the translation ({}; a translator defect):\n{}", self.error(compiled), log.lines().take(20).collect::<Vec<_>>().join("\n"));
            }
            Ok(Compiled { cubin, log })
        }
    }

    /// nvdisasm's listing of `cubin` (`-c`: code sections only).
    pub fn disassemble(&self, cubin: &[u8]) -> Result<String> {
        let dir = crate::cleanup::TempDir::new().context("cannot create a temporary directory for nvdisasm")?;
        let path = dir.path().join("kernel.cubin");
        std::fs::write(&path, cubin).with_context(|| format!("cannot write {}", path.display()))?;
        let mut cmd = crate::cleanup::command(self.nvdisasm.to_str().unwrap_or("nvdisasm"));
        cmd.arg("-c").arg(&path);
        let out = crate::compile_limit::output(&mut cmd, "a cubin's SASS (nvdisasm)").with_context(|| format!("cannot run {}", self.nvdisasm.display()))?;
        if !out.status.success() {
            bail!("nvdisasm failed: {}", String::from_utf8_lossy(&out.stderr).trim());
        }
        Ok(String::from_utf8_lossy(&out.stdout).into_owned())
    }
}
