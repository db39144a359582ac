//! The Mesa builds `make mesa` makes (scripts/mesa-noop.sh), which the noop drivers load: where each is, and
//! the environment that puts a driver on its noop drm-shim.

use anyhow::{Result, bail};
use std::path::PathBuf;

/// A Mesa build `make mesa` makes (scripts/mesa-noop.sh), which some families' drivers load.
pub struct MesaBuild {
    /// Its tools folder (`tools::TOOLS`: `mesa`, a link into the build cache).
    pub link: &'static str,
    /// The variable that names another build directory instead.
    pub var: &'static str,
    /// What it is, for messages: "Debian 12's Mesa 22.3".
    pub what: &'static str,
    /// What `make mesa` builds in it, for messages.
    pub drivers: &'static str,
}

/// The installed Mesa's own source package (Debian 12: 22.3.6).
pub static MESA_DEBIAN: MesaBuild = MesaBuild {
    link: "mesa",
    var: "BRDFPROF_MESA_DIR",
    what: "the installed Mesa (Debian 12: 22.3)",
    drivers: "Turnip, PanVK and ANV from Debian's source package of the installed Mesa, ~8 minutes on 2 cores",
};

/// Why the validation layer does not run for Mesa 25.0's drivers.
pub const MESA_25_UNVALIDATED: &str = "Debian 12's validation layer warns, on Mesa 25.0's Turnip, PanVK and NVK only, that the kernels' texel-buffer fetch (GLSL usamplerBuffer: an OpTypeSampledImage of Dim Buffer) should not be a sampled image; the same SPIR-V 1.3 kernels pass the layer on lavapipe, RADV and Mesa 22.3's drivers, so brdfprof compiles them unvalidated there and says so";

/// bookworm-backports' Mesa (25.0): Adreno 7xx and Mali Valhall.
pub static MESA_BACKPORTS: MesaBuild = MesaBuild {
    link: "mesa25",
    var: "BRDFPROF_MESA25_DIR",
    what: "bookworm-backports' Mesa 25.0",
    drivers: "Turnip and PanVK from Debian's bookworm-backports source package of Mesa 25.0, ~12 minutes on 2 cores",
};

/// The same Mesa 25.0 source again, its NVK alone (NAK is Rust, so this build needs cargo-installed bindgen and
/// cbindgen and Mesa's Rust subprojects): NVIDIA Turing and Ampere.
pub static MESA_NVK: MesaBuild = MesaBuild {
    link: "mesa25-nvk",
    var: "BRDFPROF_MESA25_NVK_DIR",
    what: "bookworm-backports' Mesa 25.0 (NVK)",
    drivers: "NVK from Debian's bookworm-backports source package of Mesa 25.0, ~12 minutes on 2 cores after ~7 minutes of cargo install for bindgen and cbindgen",
};

impl MesaBuild {
    /// Its directory (`tools::locate`: `$VAR`, beside the binary, the data directory, the build checkout; each
    /// a link `make mesa` makes into its build cache).
    pub fn dir(&self) -> PathBuf {
        crate::tools::dir(self.link)
    }

    /// A file of the build, or an error naming what is missing and what to run.
    pub fn file(&self, driver: &str, relative: &str) -> Result<PathBuf> {
        let path = self.dir().join(relative);
        if !path.is_file() {
            bail!(
                "{driver} is not built: {} is missing. Run `make mesa` (as root: it builds Mesa's drivers and their noop kernel shims once per machine; \
                 here {}), or set {} to such a build of {}",
                path.display(),
                self.drivers,
                self.var,
                self.what
            );
        }
        Ok(path)
    }
}

/// The directory of the installed Mesa's build (`MESA_DEBIAN`).
pub fn build_dir() -> PathBuf {
    MESA_DEBIAN.dir()
}

/// The variable that names the installed Mesa's build directory.
pub const BUILD_DIR_VAR: &str = "BRDFPROF_MESA_DIR";

/// The environment of a driver on a noop drm-shim: the loader sees only `icd` (the driver's devenv ICD file,
/// which names `library` in the build), `shim` answers the kernel's ioctls, and `extra` selects the GPU. Each
/// file must be in the build, or the error names it and `make mesa`.
pub fn shim_environment(
    driver: &str,
    build: &MesaBuild,
    icd: &str,
    library: &str,
    shim: &str,
    extra: &[(&str, String)],
) -> Result<Vec<(String, String)>> {
    let icd = build.file(driver, icd)?;
    build.file(driver, library)?;
    let shim = build.file(driver, shim)?;
    let mut env = vec![
        ("VK_ICD_FILENAMES".to_string(), icd.display().to_string()),
        ("VK_DRIVER_FILES".to_string(), icd.display().to_string()),
        ("LD_PRELOAD".to_string(), shim.display().to_string()),
    ];
    env.extend(extra.iter().map(|(k, v)| (k.to_string(), v.clone())));
    Ok(env)
}
