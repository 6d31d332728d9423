pub mod metric;
pub mod wall;
