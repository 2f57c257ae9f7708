fn main() {
    std::process::exit(primo_host::cli::main_with(std::env::args()));
}
