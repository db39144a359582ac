//! NVIDIA's runtime compiler (NVRTC, `libnvrtc.so.13` from the `nvidia-cuda-nvrtc` wheel), loaded at run time:
//! CUDA C++ to a cubin for one compute capability, with ptxas' resource report in its log, and nvdisasm's
//! SASS listing of the cubin. No NVIDIA GPU or driver is involved.

use anyhow::{Context, Result, anyhow, bail};
use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::path::PathBuf;
use std::sync::OnceLock;

type Program = *mut c_void;
type NvrtcResult = c_int;

/// The NVRTC C API (nvrtc.h) brdfprof calls.
struct Api {
    create: unsafe extern "C" fn(
        *mut Program,
        *const c_char,
        *const c_char,
        c_int,
        *const *const c_char,
        *const *const c_char,
    ) -> NvrtcResult,
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

/// Where the wheels `make setup` installs are (`tools::locate`: `$BRDFPROF_NVIDIA_DIR`, beside the binary, the
/// data directory, the build checkout).
pub fn install_dir() -> PathBuf {
    crate::tools::dir("nvidia")
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
    let lib = unsafe { libloading::Library::new(&lib_path) }
        .map_err(|e| not_installed(&format!("cannot load {}: {e}", lib_path.display())))?;
    // SAFETY: each symbol is looked up with the signature nvrtc.h gives it.
    let api = unsafe {
        let sym = |name: &[u8]| -> std::result::Result<*const c_void, String> {
            lib.get::<*const c_void>(name)
                .map(|s| *s)
                .map_err(|e| not_installed(&format!("{}: {e}", String::from_utf8_lossy(&name[..name.len() - 1]))))
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
        let f: libloading::Symbol<unsafe extern "C" fn(*mut c_int, *mut c_int) -> NvrtcResult> =
            lib.get(b"nvrtcVersion\0").map_err(|e| not_installed(&e.to_string()))?;
        let (mut major, mut minor) = (0, 0);
        f(&mut major, &mut minor);
        format!("NVRTC {major}.{minor}")
    };
    // Its last line names the build ("Build cuda_13.5.r13.5/compiler.37..."): the cache keys on it.
    let mut cmd = crate::cleanup::command(&nvdisasm.to_string_lossy());
    cmd.arg("--version");
    let out = crate::launch::output_quick(&mut cmd, &format!("{} --version", nvdisasm.display()))
        .map_err(|e| not_installed(&format!("{e:#}")))?;
    let nvdisasm_version = String::from_utf8_lossy(&out.stdout)
        .lines()
        .last()
        .map(str::to_string)
        .filter(|l| out.status.success() && l.starts_with("Build "))
        .ok_or_else(|| {
            not_installed(&format!(
                "{} --version printed no build line ({}): not NVIDIA's nvdisasm",
                nvdisasm.display(),
                out.status
            ))
        })?;
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
        let opts: Vec<CString> = options
            .iter()
            .map(|o| CString::new(o.as_str()))
            .collect::<Result<_, _>>()
            .context("an NVRTC option with a NUL byte")?;
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
                bail!(
                    "NVRTC cannot compile the translation ({}; a translator defect):\n{}",
                    self.error(compiled),
                    log.lines().take(20).collect::<Vec<_>>().join("\n")
                );
            }
            Ok(Compiled { cubin, log })
        }
    }

    /// nvdisasm's listing of `cubin` (`DISASSEMBLE_OPTIONS`; with `line_info`, `--print-line-info` too: each
    /// instruction's source file and line where the cubin carries them, NVRTC's `-lineinfo`).
    pub fn disassemble(&self, cubin: &[u8], line_info: bool) -> Result<String> {
        let dir = crate::cleanup::TempDir::new().context("cannot create a temporary directory for nvdisasm")?;
        let path = dir.path().join("kernel.cubin");
        std::fs::write(&path, cubin).with_context(|| format!("cannot write {}", path.display()))?;
        let mut cmd = crate::cleanup::command(self.nvdisasm.to_str().unwrap_or("nvdisasm"));
        crate::launch::bound_memory(&mut cmd)?;
        cmd.args(DISASSEMBLE_OPTIONS).args(line_info.then_some(LINE_INFO)).arg(&path);
        let out = crate::launch::output(&mut cmd, "a cubin's SASS (nvdisasm)")
            .with_context(|| format!("cannot run {}", self.nvdisasm.display()))?;
        if !out.status.success() {
            bail!(
                "{} failed ({}): {}",
                self.nvdisasm.display(),
                out.status,
                String::from_utf8_lossy(&out.stderr).trim()
            );
        }
        let listing = String::from_utf8_lossy(&out.stdout).into_owned();
        check_listing(&listing, cubin).map_err(|why| {
            anyhow!(
                "{}: its listing of the cubin is not the kernel's code ({why}); reinstall it with `make setup`",
                self.nvdisasm.display()
            )
        })?;
        Ok(listing)
    }
}

/// nvdisasm's options: code sections only, and each instruction's two 64-bit words (its control bits:
/// `nvidia::sass`).
pub const DISASSEMBLE_OPTIONS: [&str; 2] = ["-c", "-hex"];

/// nvdisasm's option that names each instruction's source line.
pub const LINE_INFO: &str = "--print-line-info-inline";

/// Bytes of one SASS instruction (Volta and later: 128-bit).
const SASS_INSTRUCTION_BYTES: u64 = 16;

/// The code section of a cubin (`.text.<kernel>`, an ELF64 section), by its size in bytes.
pub fn code_bytes(cubin: &[u8]) -> Option<u64> {
    let u16_at = |o: usize| cubin.get(o..o + 2).map(|b| u16::from_le_bytes([b[0], b[1]]));
    let u32_at = |o: usize| cubin.get(o..o + 4).map(|b| u32::from_le_bytes(b.try_into().unwrap()));
    let u64_at = |o: usize| cubin.get(o..o + 8).map(|b| u64::from_le_bytes(b.try_into().unwrap()));
    if cubin.get(0..5)? != b"\x7fELF\x02" {
        return None;
    }
    let (shoff, shentsize, shnum, shstrndx) =
        (u64_at(0x28)? as usize, u16_at(0x3a)? as usize, u16_at(0x3c)? as usize, u16_at(0x3e)? as usize);
    let section = |k: usize| shoff.checked_add(k.checked_mul(shentsize)?);
    let names = u64_at(section(shstrndx)? + 0x18)? as usize;
    let mut total = None;
    for k in 0..shnum {
        let at = section(k)?;
        let name_at = names.checked_add(u32_at(at)? as usize)?;
        let name = cubin.get(name_at..)?.split(|&b| b == 0).next()?;
        if name.starts_with(b".text.") {
            total = Some(total.unwrap_or(0) + u64_at(at + 0x20)?);
        }
    }
    total
}

/// Whether nvdisasm's `listing` is the code of `cubin`: instructions at consecutive addresses, through its
/// EXIT, one listed for every 16 bytes of the code sections (the padding after EXIT included).
pub fn check_listing(listing: &str, cubin: &[u8]) -> std::result::Result<(), String> {
    let addresses: Vec<u64> = listing
        .lines()
        .filter_map(|l| l.trim_start().strip_prefix("/*")?.split_once("*/").map(|(a, _)| a))
        .filter(|a| !a.is_empty() && a.chars().all(|c| c.is_ascii_hexdigit()))
        .filter_map(|a| u64::from_str_radix(a, 16).ok())
        .collect();
    if !listing.lines().any(|l| l.contains("EXIT")) {
        return Err(format!("no EXIT in {} instruction lines", addresses.len()));
    }
    let code = code_bytes(cubin).ok_or("the cubin has no code section")?;
    let covered = addresses.iter().max().map_or(0, |a| a + SASS_INSTRUCTION_BYTES);
    // Sections list from address 0 each, so the count, not the last address, must match their sum.
    if (addresses.len() as u64) * SASS_INSTRUCTION_BYTES != code {
        return Err(format!(
            "{} instructions listed up to byte {covered}, where the code section holds {code} bytes",
            addresses.len()
        ));
    }
    Ok(())
}
