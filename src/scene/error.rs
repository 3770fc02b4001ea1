//! The scene layer's error: a scene file that cannot be read, does not match the schema, has a
//! bad `--set` override, or holds an invalid value. Every variant names the file.

/// A scene could not be read or is invalid.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{file}: cannot read scene: {source}")]
    Io {
        /// Scene file.
        file: String,
        /// Cause.
        source: std::io::Error,
    },
    /// The file is not valid TOML or does not match the schema (unknown or missing field,
    /// wrong type).
    #[error("{file}: {message}")]
    Parse {
        /// Scene file.
        file: String,
        /// Parser message with location and field.
        message: String,
    },
    /// A value is out of range or inconsistent.
    #[error("{file}: field `{field}`: {reason}")]
    Invalid {
        /// Scene file.
        file: String,
        /// Dotted path of the field.
        field: String,
        /// What is wrong.
        reason: String,
    },
    /// A `--set FIELD=VALUE` override could not be applied.
    #[error("{file}: --set `{assignment}`: {reason}")]
    Override {
        /// Scene file.
        file: String,
        /// The override as given.
        assignment: String,
        /// What is wrong.
        reason: String,
    },
}

impl SceneError {
    /// An [`SceneError::Invalid`] for `field` (dotted path) of scene `file`: the one way every
    /// check of the scene layer reports a bad value.
    pub(crate) fn invalid(
        file: &str,
        field: impl Into<String>,
        reason: impl Into<String>,
    ) -> SceneError {
        SceneError::Invalid {
            file: file.to_string(),
            field: field.into(),
            reason: reason.into(),
        }
    }
}
