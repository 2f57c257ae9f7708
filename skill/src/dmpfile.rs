//! The JSON file of a fitted DMP (`primo dmp fit --out dmp.json`).
//!
//! ```json
//! { "format": "primo-dmp", "version": 1, "names": ["x", "y"],
//!   "dmp": { "tau": 1.0, "alpha": 25.0, "width": 1682.0,
//!            "start": [0, 0.5], "goal": [1, -0.5], "scaled": [true, true],
//!            "weights": [[...], [...]] } }
//! ```
//!
//! `format` and `version` are checked on load; a newer version is refused
//! rather than misread. The fields of `dmp` are those of
//! [`primo_core::dmp::Dmp`] (see the README for their meaning).

use serde::{Deserialize, Serialize};

use crate::{Error, HostDmp};

/// The `format` field's value.
pub const FORMAT: &str = "primo-dmp";
/// The version this primo writes and reads.
pub const VERSION: u32 = 1;

/// A DMP with the names of its DoFs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DmpFile {
    /// Always [`FORMAT`].
    pub format: String,
    /// Always [`VERSION`] when written by this primo.
    pub version: u32,
    /// DoF names, as in the demonstration's header.
    pub names: Vec<String>,
    /// The DMP itself.
    pub dmp: HostDmp,
}

#[derive(Deserialize)]
struct Header {
    format: String,
    version: u32,
}

impl DmpFile {
    /// Wraps a DMP and its DoF names.
    pub fn new(names: Vec<String>, dmp: HostDmp) -> Self {
        Self {
            format: FORMAT.into(),
            version: VERSION,
            names,
            dmp,
        }
    }

    /// Parses a file's text; `file` names it in error messages.
    pub fn parse(file: &str, text: &str) -> Result<Self, Error> {
        let at =
            |e: serde_json::Error| Error::File(format!("{file}:{}:{}: {e}", e.line(), e.column()));
        let header: Header = serde_json::from_str(text).map_err(at)?;
        if header.format != FORMAT {
            return Err(Error::File(format!(
                "{file}: format is `{}`, expected `{FORMAT}`",
                header.format
            )));
        }
        if header.version != VERSION {
            return Err(Error::File(format!(
                "{file}: unsupported version {} (this primo reads version {VERSION})",
                header.version
            )));
        }
        let parsed: Self = serde_json::from_str(text).map_err(at)?;
        if parsed.names.len() != parsed.dmp.dof() {
            return Err(Error::File(format!(
                "{file}: {} names for a DMP with {} DoF",
                parsed.names.len(),
                parsed.dmp.dof()
            )));
        }
        Ok(parsed)
    }

    /// Serializes to pretty JSON.
    pub fn to_json(&self) -> Result<String, serde_json::Error> {
        serde_json::to_string_pretty(self)
    }
}
