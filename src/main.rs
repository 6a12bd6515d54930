//! Thin command-line front over the `rodstudy` library: parse, dispatch, exit status.

fn main() {
    std::process::exit(rodstudy::cli::main());
}
