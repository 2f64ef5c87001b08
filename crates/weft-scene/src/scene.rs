//! A validated scene: solver settings, forces, cloths, colliders and the texts it came from.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use weft_collide::ShapeDesc;
use weft_solver::glam::{DQuat, DVec3};
use weft_solver::{ClothMesh, ClothParams, Forces, Method, Motion, Settings, Topology};

use crate::overrides::Override;
use crate::schema::{ContactKind, SceneFile};

/// Reads the files a scene names (OBJ meshes), by the path written in the scene.
pub trait Files {
    /// The bytes of `path`, or why they cannot be read.
    fn read(&self, path: &str) -> Result<Vec<u8>, String>;
}

/// Files relative to a directory (the scene file's own), at most
/// [`DEFAULT_MAX_FILE_BYTES`] each.
#[derive(Clone, Debug)]
pub struct DirFiles(pub PathBuf);

impl Files for DirFiles {
    fn read(&self, path: &str) -> Result<Vec<u8>, String> {
        read_regular(&self.0.join(path), DEFAULT_MAX_FILE_BYTES)
    }
}

/// Files relative to a directory, at most `max_bytes` each.
#[derive(Clone, Debug)]
pub struct CappedDirFiles {
    /// The directory paths are relative to.
    pub dir: PathBuf,
    /// The largest file read (bytes).
    pub max_bytes: u64,
}

impl Files for CappedDirFiles {
    fn read(&self, path: &str) -> Result<Vec<u8>, String> {
        read_regular(&self.dir.join(path), self.max_bytes)
    }
}

/// The largest scene or mesh file read unless the caller raises it: 256 MiB (an OBJ of about
/// eight million vertices).
pub const DEFAULT_MAX_FILE_BYTES: u64 = 256 << 20;

/// Reads `path` if it is a regular file of at most `max_bytes`: a FIFO, a device or a directory
/// is refused before it is opened (opening a FIFO would wait for a writer; `/dev/zero` never
/// ends).
pub fn read_regular(path: &Path, max_bytes: u64) -> Result<Vec<u8>, String> {
    use std::io::Read;
    let meta = std::fs::metadata(path).map_err(|e| e.to_string())?;
    if !meta.is_file() {
        return Err("not a regular file (a FIFO, device or directory is never read)".into());
    }
    let too_big = |n: u64| {
        format!(
            "the file holds {n} bytes, more than the limit of {max_bytes} (raise it with \
             --max-file-size)"
        )
    };
    if meta.len() > max_bytes {
        return Err(too_big(meta.len()));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(max_bytes.saturating_add(1)).read_to_end(&mut bytes))
        .map_err(|e| e.to_string())?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_big(bytes.len() as u64));
    }
    Ok(bytes)
}

/// Files held in memory (e.g. the attachments of an MCAP log).
#[derive(Clone, Debug, Default)]
pub struct MapFiles(pub BTreeMap<String, Vec<u8>>);

impl Files for MapFiles {
    fn read(&self, path: &str) -> Result<Vec<u8>, String> {
        self.0
            .get(path)
            .cloned()
            .ok_or_else(|| "not in the log's attachments".to_owned())
    }
}

/// A cloth ready for a solver.
#[derive(Clone, Debug)]
pub struct ClothSpec {
    /// Unique name (topic `/cloth/<name>/…`).
    pub name: String,
    /// The method (and so the solver) that simulates it.
    pub method: Method,
    /// Geometry, masses and pins.
    pub mesh: ClothMesh,
    /// The mesh's edges and wings, built once at load for the spring defaults and the build
    /// (`Topology::new(&mesh.triangles)`: replace both together).
    pub topology: Arc<Topology>,
    /// Per-family parameters.
    pub params: ClothParams,
    /// Collision thickness (m).
    pub thickness: f64,
    /// Motion of its pins.
    pub motion: Motion,
    /// Pinned particles that stay still whatever `motion` does, ascending.
    pub held: Vec<u32>,
    /// Garment seams: vertex pairs (mesh indices) to sew (empty for other cloths).
    pub seams: Vec<[u32; 2]>,
    /// Time over which the seams close (s).
    pub seam_time: f64,
    /// Vertices attached to the character's bones.
    pub attachments: Vec<AttachSpec>,
}

/// Garment vertices pinned to a bone of the scene's character.
#[derive(Clone, Debug, PartialEq)]
pub struct AttachSpec {
    /// The bone's index in the skeleton (for a glTF `model`: the joint's node index).
    pub bone: usize,
    /// The bone's name.
    pub bone_name: String,
    /// Mesh vertices of the cloth.
    pub vertices: Vec<u32>,
}

/// The scene's animated character: skeleton, clip and body.
#[derive(Clone, Debug)]
pub struct CharacterSpec {
    /// The character (animation and body); its clock is the solvers' (t = 0 at the first
    /// frame).
    pub character: std::sync::Arc<weft_character::Character>,
    /// Static friction between the body and cloth.
    pub static_friction: f64,
    /// Dynamic friction between the body and cloth.
    pub dynamic_friction: f64,
}

impl CharacterSpec {
    /// Binds `cloth`'s attachments to their bones at `time`: each attached vertex keeps its
    /// rest position's coordinates in its bone's frame at that time.
    pub fn bind(
        &self,
        cloth: &ClothSpec,
        time: f64,
    ) -> Result<Vec<weft_character::Attachment>, weft_character::AttachError> {
        let bones = self.character.animation().bones(time);
        cloth
            .attachments
            .iter()
            .map(|a| {
                weft_character::Attachment::bind(
                    a.bone,
                    a.vertices.clone(),
                    &cloth.mesh.positions,
                    &bones[a.bone].transform,
                )
            })
            .collect()
    }
}

/// The scene's skinned glTF character (`[character] model = …`): a deforming mesh collider.
#[derive(Clone, Debug)]
pub struct ModelSpec {
    /// The model file, as written in the scene.
    pub path: String,
    /// The skinned mesh, placed and played as the scene says; its clock is the solvers'.
    pub skin: std::sync::Arc<weft_character::skin::SkinCollider>,
    /// Static friction between the body and cloth.
    pub static_friction: f64,
    /// Dynamic friction between the body and cloth.
    pub dynamic_friction: f64,
}

impl ModelSpec {
    /// Binds `cloth`'s attachments to the model's joint nodes at `time`: each attached vertex
    /// keeps its rest position's coordinates in its joint's placed world frame at that time.
    pub fn bind(
        &self,
        cloth: &ClothSpec,
        time: f64,
    ) -> Result<Vec<weft_character::skin::JointAttachment>, String> {
        let world = self.skin.node_world(time);
        cloth
            .attachments
            .iter()
            .map(|a| {
                let bind = world
                    .get(a.bone)
                    .ok_or_else(|| format!("joint node {} is not in the model", a.bone))?;
                weft_character::skin::JointAttachment::bind(
                    a.bone,
                    a.vertices.clone(),
                    &cloth.mesh.positions,
                    bind,
                )
                .map_err(|e| e.to_string())
            })
            .collect()
    }
}

/// A collider ready for the collision world.
#[derive(Clone, Debug, PartialEq)]
pub struct ColliderSpec {
    /// Name.
    pub name: String,
    /// Geometry, in the collision crate's one form (f64).
    pub shape: ShapeDesc,
    /// Position (m).
    pub position: DVec3,
    /// Orientation.
    pub rotation: DQuat,
    /// Kinematic motion.
    pub motion: Motion,
    /// Static friction coefficient.
    pub static_friction: f64,
    /// Dynamic friction coefficient.
    pub dynamic_friction: f64,
}

/// Self-collision settings.
#[derive(Clone, Debug, PartialEq)]
pub struct SelfCollisionSpec {
    /// Cloths taking part.
    pub cloths: Vec<String>,
    /// Static friction between particles.
    pub static_friction: f64,
    /// Dynamic friction between particles.
    pub dynamic_friction: f64,
    /// Largest per-substep displacement as a fraction of thickness.
    pub max_displacement: f64,
    /// Extra search radius as a fraction of thickness.
    pub search_margin: f64,
    /// Whether the search margin follows the cloth's motion.
    pub adaptive_search_margin: bool,
    /// Particle or mesh-level contact.
    pub contact: ContactKind,
}

/// A validated scene.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The scene file's path as given (for messages and logs).
    pub name: String,
    /// The file's text, verbatim.
    pub source: String,
    /// The text after `--set` overrides (what was simulated).
    pub effective: String,
    /// The overrides applied.
    pub overrides: Vec<Override>,
    /// The file as deserialised, defaults filled in.
    pub file: SceneFile,
    /// Settings shared by every solver (each solver sets its own method).
    pub settings: Settings,
    /// Forces shared by every solver.
    pub forces: Forces,
    /// Cloths, sorted by name.
    pub cloths: Vec<ClothSpec>,
    /// Colliders in file order.
    pub colliders: Vec<ColliderSpec>,
    /// Self-collision, when on.
    pub self_collision: Option<SelfCollisionSpec>,
    /// The animated character, when the scene has one (a skeleton and its body).
    pub character: Option<CharacterSpec>,
    /// The skinned glTF character, when the scene's `[character]` names a `model`.
    pub model: Option<ModelSpec>,
    /// Files the scene read (OBJ meshes), by the path written in the scene.
    pub files: BTreeMap<String, Vec<u8>>,
}

impl Scene {
    /// The methods used, in cloth order, each once: a scene yields one solver per method.
    pub fn methods(&self) -> Vec<Method> {
        let mut out = Vec::new();
        for c in &self.cloths {
            if !out.contains(&c.method) {
                out.push(c.method);
            }
        }
        out
    }

    /// The resolved scene (every default filled in) as TOML.
    pub fn resolved_toml(&self) -> String {
        toml_edit::ser::to_string_pretty(&self.file).unwrap_or_else(|e| format!("# {e}\n"))
    }

    /// Directory a scene at `path` resolves its files against.
    pub fn dir_of(path: &Path) -> PathBuf {
        path.parent()
            .map(Path::to_path_buf)
            .unwrap_or_else(|| PathBuf::from("."))
    }
}
