//! naga's view of a specialised module: whether its SPIR-V front end parses it, how many functions and IR
//! expressions it makes of it, and whether naga's validator accepts it. naga's SPIR-V front end has limits
//! (it rejects some constructs drivers accept, see the notes in docs/gate.md), so a failure here is reported
//! plainly, never treated as a problem with the kernel.

use std::error::Error;

#[derive(Clone, Debug, PartialEq)]
pub enum NagaInfo {
    /// naga parsed the module.
    Parsed {
        functions: usize,
        expressions: usize,
        /// None: valid; Some(reason): naga's validator rejected it.
        invalid: Option<String>,
    },
    /// naga's SPIR-V front end could not parse the module; the reason.
    Unparsed(String),
}

/// An error and its causes, on one line.
fn chain(e: &dyn Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        text += &format!(": {s}");
        source = s.source();
    }
    text
}

/// Parses and validates `words` with naga.
pub fn analyse(words: &[u32]) -> NagaInfo {
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    let module = match naga::front::spv::parse_u8_slice(&bytes, &naga::front::spv::Options::default()) {
        Ok(m) => m,
        Err(e) => return NagaInfo::Unparsed(chain(&e)),
    };
    let functions = module.functions.len() + module.entry_points.len();
    let expressions = module.functions.iter().map(|(_, f)| f.expressions.len()).sum::<usize>()
        + module.entry_points.iter().map(|e| e.function.expressions.len()).sum::<usize>();
    let invalid = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .validate(&module)
        .err()
        .map(|e| chain(&e));
    NagaInfo::Parsed { functions, expressions, invalid }
}

impl NagaInfo {
    /// Numeric statistics (`naga/functions`, `naga/expressions`), empty when naga could not parse.
    pub fn stats(&self) -> Vec<(String, f64)> {
        match self {
            NagaInfo::Parsed { functions, expressions, .. } => {
                vec![("naga/functions".into(), *functions as f64), ("naga/expressions".into(), *expressions as f64)]
            }
            NagaInfo::Unparsed(_) => Vec::new(),
        }
    }

    /// "valid", "invalid: reason" or "cannot parse: reason".
    pub fn verdict(&self) -> String {
        match self {
            NagaInfo::Parsed { invalid: None, .. } => "valid".into(),
            NagaInfo::Parsed { invalid: Some(reason), .. } => format!("invalid: {reason}"),
            NagaInfo::Unparsed(reason) => format!("cannot parse: {reason}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn garbage_is_reported_as_unparsed() {
        assert!(matches!(analyse(&[0x0723_0203, 0, 0]), NagaInfo::Unparsed(_)));
    }
}
