//! The `caustic` command line: render scenes to images, export patches as OBJ, benchmark, or
//! open the viewer. Parsing and the commands live in `src/cli/`.

mod cli;

fn main() -> std::process::ExitCode {
    return_large_allocations();
    match cli::run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("{}", cli::error_report(&error));
            std::process::ExitCode::FAILURE
        }
    }
}

/// Serves every allocation of 16 MiB or more from its own mapping, given back to the system
/// when freed (glibc). By default glibc raises this threshold to the size of each large block
/// freed (up to 32 MiB), so a 1920×1080 render's per-pass buffers of 16–32 MiB (photon counts,
/// the grid's bucket starts) come from malloc's heaps after the first pass and fragment them,
/// and the peak grows pass by pass (`caustic bench memory`). A lower threshold would make
/// small renders' passes fault in fresh pages.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[allow(unsafe_code)]
fn return_large_allocations() {
    // SAFETY: `mallopt` only sets a parameter of glibc's malloc; it is called before any other
    // thread exists, and any value up to 32 MiB is valid for `M_MMAP_THRESHOLD`.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 16 << 20);
    }
}

/// Elsewhere the system allocator is left as it is.
#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn return_large_allocations() {}
