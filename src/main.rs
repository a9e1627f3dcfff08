fn main() {
    // Rust ignores SIGPIPE, so a print to a closed pipe (`directlab chi2 --list | head`)
    // panics; the default action ends the process quietly, as `ls | head` does.
    #[cfg(unix)]
    // SAFETY: called first thing in main, before any thread exists; SIG_DFL is a valid
    // disposition for SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    std::process::exit(directlab::cli::main());
}
