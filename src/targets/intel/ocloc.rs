//! Intel's offline compiler (`ocloc`, Debian's intel-opencl-icd: IGC, Intel's production OpenCL/Level Zero
//! compiler) run as a process on OpenCL C, with no Intel GPU or driver, and its disassembler (`ocloc disasm`,
//! which lists the ISA through IGA, `libiga64.so`, and the binary's patch tokens). Every run is under the
//! compile limit (`launch::output`).

use anyhow::{Context, Result, anyhow, bail};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// ocloc and what its output depends on.
pub struct Tools {
    pub ocloc: PathBuf,
    /// "ocloc 22.43.24595 (libigc 1.0.12504 ...)": the driver version and IGC's library, for the cache key.
    pub version: String,
    /// The directory with `libiga64.so` (ocloc dlopens it to disassemble).
    pub iga_dir: PathBuf,
}

/// `$BRDFPROF_OCLOC`, else ocloc on PATH (Debian: /usr/bin/ocloc).
fn ocloc_path() -> PathBuf {
    match std::env::var_os("BRDFPROF_OCLOC").filter(|d| !d.is_empty()) {
        Some(p) => PathBuf::from(p),
        None => std::env::var_os("PATH")
            .and_then(|paths| std::env::split_paths(&paths).map(|d| d.join("ocloc")).find(|p| p.is_file()))
            .unwrap_or_else(|| PathBuf::from("/usr/bin/ocloc")),
    }
}

/// Where `make setup` links `libiga64.so` (`tools::locate`: `$BRDFPROF_INTEL_DIR`, beside the binary, the data
/// directory, the build checkout).
pub fn iga_dir() -> PathBuf {
    crate::tools::dir("intel")
}

fn not_installed(why: &str) -> String {
    format!(
        "Intel compiler not installed: run `make setup` (it installs Debian's intel-opencl-icd, whose ocloc runs IGC with no Intel GPU, and links IGA's libiga64.so into {}); {why}",
        iga_dir().display()
    )
}

/// IGC's library as ocloc loads it: its resolved name and size stand for its version (Debian ships no
/// version query for it).
fn igc_identity() -> String {
    ["/usr/lib/x86_64-linux-gnu/libigc.so.1", "/usr/lib/libigc.so.1"]
        .iter()
        .find_map(|p| {
            let real = std::fs::canonicalize(p).ok()?;
            let len = std::fs::metadata(&real).ok()?.len();
            Some(format!("{} ({len} bytes)", real.display()))
        })
        .unwrap_or_else(|| "libigc not found".into())
}

fn load() -> std::result::Result<Tools, String> {
    let ocloc = ocloc_path();
    if ocloc.is_dir() {
        return Err(not_installed(&format!(
            "{} is a directory, not the ocloc executable (BRDFPROF_OCLOC names the program itself)",
            ocloc.display()
        )));
    }
    if !ocloc.is_file() {
        return Err(not_installed(&format!("{} is missing", ocloc.display())));
    }
    let iga_dir = iga_dir();
    if !iga_dir.join("libiga64.so").exists() {
        return Err(not_installed(&format!(
            "{} is missing (ocloc cannot disassemble without it)",
            iga_dir.join("libiga64.so").display()
        )));
    }
    // `ocloc query OCL_DRIVER_VERSION` writes the version to a file of that name in its working directory.
    let dir = crate::cleanup::TempDir::new().map_err(|e| not_installed(&format!("no temporary directory: {e}")))?;
    let mut cmd = crate::cleanup::command(ocloc.to_str().unwrap_or("ocloc"));
    cmd.args(["query", "OCL_DRIVER_VERSION"]).current_dir(dir.path());
    let out = crate::launch::output(&mut cmd, "ocloc's version query")
        .map_err(|e| not_installed(&format!("cannot run {}: {e:#}", ocloc.display())))?;
    let driver = std::fs::read_to_string(dir.path().join("OCL_DRIVER_VERSION")).unwrap_or_default();
    let driver = driver.trim_matches(|c: char| c.is_whitespace() || c == '\0');
    if !out.status.success() || driver.is_empty() {
        return Err(not_installed(&format!("{} does not answer `query OCL_DRIVER_VERSION`", ocloc.display())));
    }
    Ok(Tools { ocloc, version: format!("ocloc {driver} ({})", igc_identity()), iga_dir })
}

/// The tools, checked once per process; an error naming the fix when they are not installed.
pub fn tools() -> Result<&'static Tools> {
    static TOOLS: OnceLock<std::result::Result<Tools, String>> = OnceLock::new();
    TOOLS.get_or_init(load).as_ref().map_err(|e| anyhow!("{e}"))
}

/// The OpenCL build option that keeps source lines and nothing else of the debug information.
pub const LINE_TABLES: &str = "-gline-tables-only";

/// What one compilation produced.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct Binary {
    /// IGA's listing of the kernel heap (`ocloc disasm`).
    pub listing: String,
    /// The patch-token dump (`PTM.txt`): SIMD width, GRF count, scratch space.
    pub tokens: String,
    /// The device binary's size in bytes.
    pub bytes: usize,
    /// ocloc's build log (warnings).
    pub log: String,
    /// IGC's own listings of the kernel with their `// File:` and `// Line` comments (`compile_with_lines`), by
    /// SIMD width (IGC dumps every width it compiled); empty otherwise.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub lines_listings: std::collections::BTreeMap<u32, String>,
}

/// A kernel the device cannot compile for a reason of the device's own (fp64 where it has none): the family
/// leaves the kernel out with this note, as RADV leaves out fp16 on a family without shaderFloat16.
#[derive(Debug)]
pub struct Unsupported {
    pub reason: String,
}

impl std::fmt::Display for Unsupported {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.reason)
    }
}

impl std::error::Error for Unsupported {}

impl Tools {
    fn run(
        &self,
        args: &[&std::ffi::OsStr],
        cwd: &Path,
        what: &str,
        dump: Option<&Path>,
    ) -> Result<std::process::Output> {
        let mut cmd = crate::cleanup::command(self.ocloc.to_str().unwrap_or("ocloc"));
        crate::launch::bound_memory(&mut cmd)?;
        cmd.args(args).current_dir(cwd).env("LD_LIBRARY_PATH", &self.iga_dir);
        if let Some(dir) = dump {
            // IGC's debug knobs (read from the environment): its shader dumps, into `dir`.
            cmd.env("IGC_ShaderDumpEnable", "1").env("IGC_DumpToCustomDir", dir);
        }
        let out =
            crate::launch::output(&mut cmd, what).with_context(|| format!("cannot run {}", self.ocloc.display()))?;
        Ok(out)
    }

    /// Compiles the OpenCL C `source` for ocloc device `device` (`tgllp`) with `options` and disassembles it.
    pub fn compile(&self, source: &str, device: &str, options: &str, what: &str) -> Result<Binary> {
        self.compile_in(source, device, options, what, false)
    }

    /// `compile` with line tables and IGC's shader dump, whose listing of the kernel at the SIMD width IGC chose
    /// names each instruction's source file and line (`Binary::lines_listing`); ocloc's own listing carries
    /// none. `-gline-tables-only`, not `-g`: full debug information changes IGC's code (ggx on tgllp: 1012
    /// instructions against 879), line tables alone do not.
    pub fn compile_with_lines(&self, source: &str, device: &str, options: &str, what: &str) -> Result<Binary> {
        self.compile_in(source, device, &format!("{options} {LINE_TABLES}"), what, true)
    }

    fn compile_in(&self, source: &str, device: &str, options: &str, what: &str, lines: bool) -> Result<Binary> {
        let dir = crate::cleanup::TempDir::new().context("cannot create a temporary directory for ocloc")?;
        let src = dir.path().join("brdfprof_kernel.cl");
        std::fs::write(&src, source).with_context(|| format!("cannot write {}", src.display()))?;
        let out_dir = dir.path().join("out");
        let os = |s: &str| std::ffi::OsString::from(s);
        let args = [
            os("compile"),
            os("-file"),
            src.clone().into_os_string(),
            os("-device"),
            os(device),
            os("-options"),
            os(options),
            os("-q"),
            os("-out_dir"),
            out_dir.clone().into_os_string(),
        ];
        let dump_dir = dir.path().join("igc-dump");
        let dump_into = lines.then_some(dump_dir.as_path());
        let out = self.run(&args.iter().map(|a| a.as_os_str()).collect::<Vec<_>>(), dir.path(), what, dump_into)?;
        let log = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
        // The shader dump's own notice is not the compiler's.
        let log: String =
            log.lines().filter(|l| !l.starts_with("ShaderDumpEnable Warning")).collect::<Vec<_>>().join("\n");
        if !out.status.success() {
            return Err(self.compile_error(&args, dir.path(), device, what));
        }
        let no_binary = |why: String| {
            anyhow!(
                "{}: `ocloc compile` for {device} exited 0 but wrote no device binary ({why}) in {}: {}",
                self.ocloc.display(),
                out_dir.display(),
                if log.trim().is_empty() { "it printed nothing" } else { log.trim() }
            )
        };
        let bin = std::fs::read_dir(&out_dir)
            .map_err(|e| no_binary(e.to_string()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .find(|p| p.extension().is_some_and(|x| x == "bin") && p.is_file())
            .ok_or_else(|| no_binary("no .bin file".into()))?;
        let bytes = std::fs::metadata(&bin).map_err(|e| no_binary(e.to_string()))?.len() as usize;
        let (listing, tokens) = self.disassemble(bin, dir.path(), device, what)?;
        let mut binary =
            Binary { listing, tokens, bytes, log: log.trim().to_string(), lines_listings: Default::default() };
        if lines {
            binary.lines_listings = dumped_listings(&dump_dir)
                .with_context(|| format!("{what}: IGC's shader dump in {}", dump_dir.display()))?;
        }
        Ok(binary)
    }

    /// The error of an ocloc compile that failed: compiled again without -q, which hides the compiler's
    /// messages, for the reason (the translation needs an fp64 `device` has not, or a translator defect).
    fn compile_error(&self, args: &[std::ffi::OsString], dir: &Path, device: &str, what: &str) -> anyhow::Error {
        let loud: Vec<&std::ffi::OsStr> =
            args.iter().filter(|a| a.as_os_str() != "-q").map(|a| a.as_os_str()).collect();
        let again = match self.run(&loud, dir, what, None) {
            Ok(again) => again,
            Err(e) => return e,
        };
        let log = format!("{}{}", String::from_utf8_lossy(&again.stdout), String::from_utf8_lossy(&again.stderr));
        let errors: Vec<&str> = log.lines().filter(|l| l.contains("error:")).take(5).collect();
        if let Some(e) = errors.iter().find(|l| l.contains("cl_khr_fp64")) {
            return Unsupported { reason: format!("{device} has no fp64 (cl_khr_fp64); ocloc: {}", e.trim()) }.into();
        }
        anyhow!(
            "ocloc cannot compile the OpenCL C translation for {device} (a translator defect):\n{}",
            if errors.is_empty() { log.lines().take(20).collect::<Vec<_>>().join("\n") } else { errors.join("\n") }
        )
    }

    /// The ISA listing and patch tokens of the device binary `bin` (`ocloc disasm` into `dir`).
    fn disassemble(&self, bin: PathBuf, dir: &Path, device: &str, what: &str) -> Result<(String, String)> {
        let os = |s: &str| std::ffi::OsString::from(s);
        let dump = dir.join("disasm");
        let args = [
            os("disasm"),
            os("-file"),
            bin.into_os_string(),
            os("-device"),
            os(device),
            os("-dump"),
            dump.clone().into_os_string(),
        ];
        let out = self.run(
            &args.iter().map(|a| a.as_os_str()).collect::<Vec<_>>(),
            dir,
            &format!("{what}: its ISA (ocloc disasm)"),
            None,
        )?;
        let read = |name: &str| {
            crate::io::read_bounded(&dump.join(name), crate::launch::MAX_OUTPUT_BYTES as u64)
                .map(|b| String::from_utf8_lossy(&b).into_owned())
        };
        let listing = read("brdfprof_kernel_KernelHeap.asm").map_err(|e| {
            anyhow!(
                "{}: `ocloc disasm` for {device} wrote no ISA listing ({e}; it needs {} to load IGA): {}",
                self.ocloc.display(),
                self.iga_dir.join("libiga64.so").display(),
                String::from_utf8_lossy(&out.stderr).trim()
            )
        })?;
        let tokens = read("PTM.txt").map_err(|e| {
            anyhow!("{}: `ocloc disasm` for {device} wrote no patch tokens ({e})", self.ocloc.display())
        })?;
        Ok((listing, tokens))
    }
}

/// IGC's dumped listings of the kernel (`*_simd{W}_entry_*.asm`), by SIMD width W, each bounded in size.
fn dumped_listings(dir: &Path) -> Result<std::collections::BTreeMap<u32, String>> {
    let mut out = std::collections::BTreeMap::new();
    for entry in std::fs::read_dir(dir).with_context(|| format!("cannot read {}", dir.display()))? {
        let path = entry?.path();
        let Some(name) = path.file_name().and_then(|n| n.to_str()) else { continue };
        let width = name
            .split_once("_simd")
            .and_then(|(_, rest)| rest.split_once("_entry_"))
            .filter(|_| name.ends_with(".asm"))
            .and_then(|(w, _)| w.parse::<u32>().ok());
        if let Some(w) = width {
            let bytes = crate::io::read_bounded(&path, crate::launch::MAX_OUTPUT_BYTES as u64)?;
            out.insert(w, String::from_utf8_lossy(&bytes).into_owned());
        }
    }
    if out.is_empty() {
        bail!("IGC wrote no listing (*_simd*_entry_*.asm)");
    }
    Ok(out)
}
