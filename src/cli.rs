//! The `blmesh` command line (to be filled in).

pub fn main() -> i32 {
    0
}
