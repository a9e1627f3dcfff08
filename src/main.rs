fn main() {
    std::process::exit(directlab::cli::main());
}
