fn main() -> std::process::ExitCode {
    blmesh::cli::main()
}
