//! The one cost rule every compile-only target follows (`schedule`), and the listing parsers and rate tables
//! it reads, per vendor's compiler: ACO's perfinfo (`aco`, AMD families in `amd`), ptxas' SASS and NAK's assembly
//! (`nvidia`), IGA's and brw's Gen ISA (`intel`), ir3's statistics (`ir3`), the Bifrost/Valhall compiler's
//! (`mali`). Text in, numbers out: the compilers and drivers that print the text live in the application.

pub mod aco;
pub mod amd;
pub mod intel;
pub mod ir3;
pub mod mali;
pub mod nvidia;
pub mod schedule;

/// One statistic a compiler's output gives: its name, what it is, its value (the executable it belongs to is
/// the caller's).
#[derive(Clone, Debug, PartialEq)]
pub struct Stat {
    pub name: String,
    pub description: String,
    pub value: f64,
}

impl Stat {
    pub fn new(name: impl Into<String>, description: impl Into<String>, value: f64) -> Self {
        Stat { name: name.into(), description: description.into(), value }
    }
}

/// The value of driver statistic `name` of any executable in a report row's statistics (`driver/<executable>/
/// <name>`), summed (a compute pipeline has one).
pub fn driver_stat(stats: &std::collections::BTreeMap<String, f64>, name: &str) -> Option<f64> {
    let suffix = format!("/{name}");
    let v: Vec<f64> = stats
        .iter()
        .filter(|(k, _)| k.starts_with("driver/") && k.ends_with(&suffix) && k.matches('/').count() == 2)
        .map(|(_, v)| *v)
        .collect();
    (!v.is_empty()).then(|| v.iter().sum())
}
