fn main() {
    std::process::exit(blmesh::cli::main());
}
