//! Reading character files from disk; every error names the file. Parsing is done by the
//! modules that own each format ([`crate::bvh`]).

use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::body_table::BodyTable;
use crate::bvh::{Bvh, BvhOptions, parse_bvh};
use crate::error::{BodyError, BvhError};
use crate::garment::{GarmentError, GarmentSpec};
use crate::skin::{AnimationChoice, BufferSource, SkinError, SkinnedMesh, parse_gltf_slice};

/// A character file that cannot be read or parsed.
#[derive(Debug, Error)]
pub enum LoadError {
    /// The file cannot be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The file is not valid BVH.
    #[error("{path}: {source}")]
    Bvh {
        /// The file.
        path: PathBuf,
        /// Why, with the line.
        source: BvhError,
    },
    /// The file is not a valid body table.
    #[error("{path}: {source}")]
    Body {
        /// The file.
        path: PathBuf,
        /// Why, with the line.
        source: BodyError,
    },
    /// The file is not a valid garment.
    #[error("{path}: {source}")]
    Garment {
        /// The file.
        path: PathBuf,
        /// Why, with the line.
        source: GarmentError,
    },
    /// The file is not a usable skinned glTF.
    #[error("{path}: {source}")]
    Skin {
        /// The file (or the external buffer it names).
        path: PathBuf,
        /// Why.
        source: SkinError,
    },
}

fn read_text(path: &Path) -> Result<String, LoadError> {
    std::fs::read_to_string(path).map_err(|source| LoadError::Io {
        path: path.to_owned(),
        source,
    })
}

/// Reads and parses a BVH file.
pub fn read_bvh(path: &Path, options: &BvhOptions) -> Result<Bvh, LoadError> {
    let text = read_text(path)?;
    parse_bvh(&text, options).map_err(|source| LoadError::Bvh {
        path: path.to_owned(),
        source,
    })
}

/// Reads and parses a body table (TOML, see [`BodyTable`]).
pub fn read_body_table(path: &Path) -> Result<BodyTable, LoadError> {
    let text = read_text(path)?;
    BodyTable::from_toml(&text).map_err(|source| LoadError::Body {
        path: path.to_owned(),
        source,
    })
}

/// Reads and parses a garment file (TOML, see [`GarmentSpec`]).
pub fn read_garment(path: &Path) -> Result<GarmentSpec, LoadError> {
    let text = read_text(path)?;
    GarmentSpec::from_toml(&text).map_err(|source| LoadError::Garment {
        path: path.to_owned(),
        source,
    })
}

/// Reads a skinned, animated mesh from a `.gltf` or `.glb` file; external buffers are read
/// from paths relative to the file; the first animation plays.
pub fn read_skinned_gltf(path: &Path) -> Result<SkinnedMesh, LoadError> {
    read_skinned_gltf_with(path, &AnimationChoice::First)
}

/// [`read_skinned_gltf`] playing the animation `animation` chooses.
pub fn read_skinned_gltf_with(
    path: &Path,
    animation: &AnimationChoice,
) -> Result<SkinnedMesh, LoadError> {
    let bytes = std::fs::read(path).map_err(|source| LoadError::Io {
        path: path.to_owned(),
        source,
    })?;
    let skin_error = |source| LoadError::Skin {
        path: path.to_owned(),
        source,
    };
    let (doc, sources) = parse_gltf_slice(&bytes).map_err(skin_error)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let buffers = sources
        .into_iter()
        .map(|s| match s {
            BufferSource::Data(d) => Ok(d),
            BufferSource::External(uri) => {
                let file = dir.join(&uri);
                std::fs::read(&file).map_err(|source| LoadError::Io { path: file, source })
            }
        })
        .collect::<Result<Vec<_>, _>>()?;
    SkinnedMesh::from_document_with(&doc, &buffers, animation).map_err(skin_error)
}
