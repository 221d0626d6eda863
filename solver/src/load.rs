//! Loading a case file: parse, apply overrides, then every check, those of `config` first and
//! then the ones that need the case's derived sound speed, so that a case that cannot run is
//! refused with the field and the reason before anything is built.

use crate::config::{Case, ConfigError};
use crate::derived::check_bottom_outlet;
use std::path::Path;

impl Case {
    pub fn from_path(path: &Path) -> Result<Case, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Case::from_yaml(&text, &path.display().to_string())
    }

    /// Reads `path` with `overrides` applied first, each `key.path=value` (a YAML value; a
    /// number in the path indexes a list, `phases.1.sediment.ks_over_d50=7`): the same case at
    /// another resolution or roughness without a second file. Every override is validated as
    /// the file is.
    pub fn from_path_with(path: &Path, overrides: &[String]) -> Result<Case, ConfigError> {
        if overrides.is_empty() {
            return Case::from_path(path);
        }
        let origin = format!("{} (with {})", path.display(), overrides.join(", "));
        let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Io {
            path: path.display().to_string(),
            source,
        })?;
        let invalid = |field: &str, reason: String| ConfigError::Invalid {
            path: origin.clone(),
            field: field.to_string(),
            reason,
        };
        let mut doc: serde_norway::Value =
            serde_norway::from_str(&text).map_err(|e| invalid("(top level)", e.to_string()))?;
        for o in overrides {
            let (key, value) = o
                .split_once('=')
                .ok_or_else(|| invalid(o, "an override is key=value".into()))?;
            let value: serde_norway::Value =
                serde_norway::from_str(value).map_err(|e| invalid(key, e.to_string()))?;
            let mut node = &mut doc;
            let parts: Vec<&str> = key.split('.').collect();
            for (i, part) in parts.iter().enumerate() {
                let last = i + 1 == parts.len();
                node = match node {
                    serde_norway::Value::Sequence(items) => {
                        let k: usize = part
                            .parse()
                            .map_err(|_| invalid(key, format!("{part} is not a list index")))?;
                        let len = items.len();
                        items.get_mut(k).ok_or_else(|| {
                            invalid(key, format!("index {k} past the list's {len} items"))
                        })?
                    }
                    serde_norway::Value::Mapping(map) if last => {
                        map.insert(serde_norway::Value::String(part.to_string()), value.clone());
                        break;
                    }
                    serde_norway::Value::Mapping(map) => map
                        .get_mut(*part)
                        .ok_or_else(|| invalid(key, format!("the file has no section {part}")))?,
                    _ => return Err(invalid(key, format!("{part} is not a section or a list"))),
                };
                if last {
                    *node = value.clone();
                }
            }
        }
        let text =
            serde_norway::to_string(&doc).map_err(|e| invalid("(top level)", e.to_string()))?;
        Case::from_yaml(&text, &origin)
    }

    /// Parses and validates a case; `origin` names the source in error messages.
    pub fn from_yaml(text: &str, origin: &str) -> Result<Case, ConfigError> {
        let de = serde_norway::Deserializer::from_str(text);
        let case: Case = serde_path_to_error::deserialize(de).map_err(|e| {
            let field = e.path().to_string();
            ConfigError::Parse {
                path: origin.to_string(),
                field: if field == "." {
                    "(top level)".to_string()
                } else {
                    field
                },
                reason: {
                    // serde prefixes the path, which the message already names.
                    let reason = e.inner().to_string();
                    let prefix = format!("{}: ", e.path());
                    reason.strip_prefix(&prefix).unwrap_or(&reason).to_string()
                },
            }
        })?;
        case.validate()
            .and_then(|()| check_bottom_outlet(&case))
            .map_err(|(field, reason)| ConfigError::Invalid {
                path: origin.to_string(),
                field,
                reason,
            })?;
        Ok(case)
    }
}
