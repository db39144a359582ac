//! What a driver writes on stderr (fd 2) while one call runs, captured in a memory file: PanVK's compiler
//! prints its statistics there (`SHADER-DB: ...`) and nowhere else. Lines that are not the driver's statistics
//! go back to the real stderr afterwards, so nothing the user should see is lost.

use anyhow::{Context, Result, bail};
use std::io::{Read, Seek, Write};
use std::os::fd::{AsRawFd, FromRawFd};

/// Only one capture at a time: fd 2 is the process'.
static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Runs `work` with fd 2 redirected into a memory file; returns its result and what it wrote there.
pub fn capture<T>(work: impl FnOnce() -> T) -> Result<(T, String)> {
    let _guard = LOCK.lock().unwrap_or_else(|e| e.into_inner());
    // SAFETY: plain fd calls; every fd opened here is closed or owned by a File before returning.
    let (saved, mut file) = unsafe {
        let fd = libc::memfd_create(c"brdfprof-stderr".as_ptr(), libc::MFD_CLOEXEC);
        if fd < 0 {
            bail!("cannot capture the driver's stderr: memfd_create: {}", std::io::Error::last_os_error());
        }
        let file = std::fs::File::from_raw_fd(fd);
        let saved = libc::dup(2);
        if saved < 0 {
            bail!("cannot capture the driver's stderr: dup: {}", std::io::Error::last_os_error());
        }
        libc::fflush(std::ptr::null_mut());
        if libc::dup2(file.as_raw_fd(), 2) < 0 {
            libc::close(saved);
            bail!("cannot capture the driver's stderr: dup2: {}", std::io::Error::last_os_error());
        }
        (saved, file)
    };
    let value = work();
    // SAFETY: restores the saved fd 2 and closes the copy.
    unsafe {
        libc::fflush(std::ptr::null_mut());
        libc::dup2(saved, 2);
        libc::close(saved);
    }
    let mut text = String::new();
    file.rewind().context("reading the captured stderr")?;
    file.take(brdfprof_process::launch::MAX_OUTPUT_BYTES as u64)
        .read_to_string(&mut text)
        .context("reading the captured stderr")?;
    Ok((value, text))
}

/// Writes captured lines to the real stderr.
pub fn pass_on(lines: &[String]) {
    let mut err = std::io::stderr().lock();
    for line in lines {
        let _ = writeln!(err, "{line}");
    }
}
