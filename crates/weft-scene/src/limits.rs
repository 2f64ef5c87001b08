//! Limits a load enforces before it reads or allocates: the largest file read, and the memory
//! the scene may need once built, estimated from its particle count before any cloth exists.

use crate::scene::{ClothSpec, DEFAULT_MAX_FILE_BYTES, Scene, SelfCollisionSpec};
use crate::schema::{
    ContactKind, DEFAULT_RESOLUTION, DEFAULT_SIZE, DEFAULT_THICKNESS, RESOLUTION_RANGE, SceneFile,
};
use weft_solver::Method;

/// What a load may read and allocate.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Largest scene or mesh file read (bytes).
    pub max_file_bytes: u64,
    /// Memory the built scene may need (bytes), and where that figure comes from (for the
    /// message, e.g. "MemAvailable" or "--max-memory"); `None`: no limit.
    pub max_memory: Option<(u64, String)>,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_file_bytes: DEFAULT_MAX_FILE_BYTES,
            max_memory: None,
        }
    }
}

impl Limits {
    /// The command line's defaults: files up to [`DEFAULT_MAX_FILE_BYTES`], and a scene no
    /// larger than the memory available now ([`available_memory`]), where that is known.
    pub fn available() -> Self {
        Self {
            max_file_bytes: DEFAULT_MAX_FILE_BYTES,
            max_memory: available_memory()
                .map(|b| (b, "the memory available, MemAvailable".to_owned())),
        }
    }
}

/// The `KEY:  N kB` line of a /proc file, in bytes (`None` where there is no such file or line).
fn proc_kib(path: &str, key: &str) -> Option<u64> {
    let text = std::fs::read_to_string(path).ok()?;
    let prefix = format!("{key}:");
    let line = text.lines().find(|l| l.starts_with(&prefix))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// This process's peak resident memory so far (`VmHWM` in /proc/self/status), in bytes.
pub fn peak_memory() -> Option<u64> {
    proc_kib("/proc/self/status", "VmHWM")
}

/// `MemAvailable` from /proc/meminfo, in bytes (`None` where there is no such file).
pub fn available_memory() -> Option<u64> {
    proc_kib("/proc/meminfo", "MemAvailable")
}

/// Bytes one particle of a built scene needs under `method`: its mesh (positions, masses,
/// triangles, constraints), the solver's store, domains and scratch (the spring methods' forces,
/// the implicit method's linearised springs, rows and conjugate-gradient vectors), and one
/// frame of log messages with their encode and compression buffers. The peak resident set of
/// `weft run --out` over a 512² grid with every constraint family on, less [`BASE_BYTES`]:
/// XPBD and PBD 1,452, mass-spring 2,072, implicit mass-spring 2,968 bytes a particle
/// (2026-12-07, Xeon, AVX-512 path); rounded up.
pub fn bytes_per_particle(method: Method) -> u64 {
    match method {
        Method::Xpbd | Method::Pbd => 1600,
        Method::MassSpring => 2300,
        Method::ImplicitMassSpring => 3200,
    }
}

/// Extra bytes per self-collision member (its cell in the grid, anchors, tags, the contact
/// sweep's corrections): measured 240 on a 512² grid, rounded up. The candidate pairs are
/// counted apart ([`BYTES_PER_PAIR`]).
pub const PER_PARTICLE_SELF_COLLISION: u64 = 400;

/// Bytes a candidate pair of self-collision costs at most: its entry in the list (two `u32`
/// indices and an `f64` target, 16 bytes, with the room a growing list keeps) and, while it
/// touches, the sweep's two 32-byte corrections. Measured: 84 bytes a listed pair at the
/// peak of two coincident 48² sheets 10 m thick, where every listed pair touches.
pub const BYTES_PER_PAIR: u64 = 96;

/// The process before any scene: the binary, the allocator's arenas, the threads' stacks and
/// the log's compressor (a run of a 20 × 20 cloth peaks at 12–25 MiB).
pub const BASE_BYTES: u64 = 32 << 20;

/// The largest skin (as a fraction of the thickness) an adaptive self-collision list keeps
/// while it is dense; it grows thicker only while the list is sparse.
const DENSE_MARGIN: f64 = 1.0;

/// A self-collision member cloth as the estimate sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Member {
    /// Its particles.
    pub particles: u64,
    /// Its rest area (m²).
    pub area: f64,
    /// Its collision thickness (m).
    pub thickness: f64,
}

/// A bound on the candidate pairs self-collision lists for `members` with search margin
/// `margin` (the starting one when `adaptive`). A particle's partners lie within
/// R = t (1 + m) of it (t the largest thickness); layers the contacts keep t apart fit
/// 2R/t + 1 deep into that ball, each holding at most π R² / a particles (a the smallest area
/// per particle); and no particle has more partners than the other members.
pub fn self_collision_pairs(members: &[Member], margin: f64, adaptive: bool) -> u64 {
    let total: u64 = members.iter().map(|m| m.particles).sum();
    let t = members.iter().map(|m| m.thickness).fold(0.0, f64::max);
    if total < 2 || t <= 0.0 {
        return 0;
    }
    let margin = if adaptive {
        margin.max(DENSE_MARGIN)
    } else {
        margin
    };
    let reach = t * (1.0 + margin);
    let per_particle = members
        .iter()
        .filter(|m| m.particles > 0)
        .map(|m| m.area / m.particles as f64)
        .fold(f64::INFINITY, f64::min);
    let layers = 2.0 * reach / t + 1.0;
    let partners =
        (layers * std::f64::consts::PI * reach * reach / per_particle).min((total - 1) as f64);
    // Each pair is listed once.
    (total as f64 * partners / 2.0).ceil() as u64
}

/// A bound on the element pairs mesh-level cloth contact lists for `members`. Pairs are listed
/// while their boxes lie within D = (1 + s) t (the reach t, the largest thickness, and the
/// contact's default skin of s t); an element's box is at most h = √(2 a) across (a the smallest area per particle), so
/// a vertex's partners lie within D + h in each of the 2D/t + 1 layers contact keeps t apart,
/// π (D + h)² / a particles a layer. Each particle brings two triangles and three edges: its
/// vertex meets two triangles of each partner and its three edges three of each partner's,
/// 6.5 pairs per partner, each listed once.
pub fn mesh_contact_pairs(members: &[Member]) -> u64 {
    let total: u64 = members.iter().map(|m| m.particles).sum();
    let t = members.iter().map(|m| m.thickness).fold(0.0, f64::max);
    if total < 2 || t <= 0.0 {
        return 0;
    }
    let a = members
        .iter()
        .filter(|m| m.particles > 0)
        .map(|m| m.area / m.particles as f64)
        .fold(f64::INFINITY, f64::min);
    let d = (1.0 + weft_collide::ClothContactParams::default().skin) * t;
    let r = d + (2.0 * a).sqrt();
    let partners = ((2.0 * d / t + 1.0) * std::f64::consts::PI * r * r / a).min((total - 1) as f64);
    (total as f64 * partners * 6.5 / 2.0).ceil() as u64
}

/// The candidate pairs of `members` under contact `kind` (see [`self_collision_pairs`] and
/// [`mesh_contact_pairs`]).
pub fn contact_pairs(members: &[Member], kind: ContactKind, margin: f64, adaptive: bool) -> u64 {
    match kind {
        ContactKind::Particles => self_collision_pairs(members, margin, adaptive),
        ContactKind::Mesh => mesh_contact_pairs(members),
    }
}

/// The memory a scene needs once built and running: the process, its cloths' particles (a
/// count per cloth, with its method), and with self-collision its `members` and their
/// candidate `pairs` (see [`self_collision_pairs`]).
pub fn estimate_bytes(cloths: &[(Method, u64)], members: u64, pairs: u64) -> u64 {
    let particles = (cloths.iter())
        .map(|&(m, n)| n.saturating_mul(bytes_per_particle(m)))
        .fold(0u64, u64::saturating_add);
    BASE_BYTES
        .saturating_add(particles)
        .saturating_add(members.saturating_mul(PER_PARTICLE_SELF_COLLISION))
        .saturating_add(pairs.saturating_mul(BYTES_PER_PAIR))
}

/// Every grid cloth of `file` as the estimate sees it, read from its keys alone (a mesh or
/// garment cloth's file is capped by [`Limits::max_file_bytes`] instead), and whether
/// self-collision takes it in.
pub(crate) fn grid_members(file: &SceneFile) -> Vec<(String, Member, bool)> {
    let chosen = (file.self_collision.as_ref())
        .filter(|s| s.enabled)
        .map(|s| s.cloths.clone());
    file.cloth
        .iter()
        .filter(|(_, s)| s.mesh.is_none() && s.garment.is_none())
        .map(|(name, s)| {
            let [nx, ny] = s.resolution.unwrap_or(DEFAULT_RESOLUTION);
            // Counts out of range count nothing: the resolution is refused by name instead.
            let fits = |n: i64| RESOLUTION_RANGE.contains(&n);
            let particles = match fits(nx) && fits(ny) {
                true => nx as u64 * ny as u64,
                false => 0,
            };
            let [w, h] = s.size.unwrap_or(DEFAULT_SIZE);
            let member = Member {
                particles,
                area: (w * h).abs(),
                thickness: s.thickness.unwrap_or(DEFAULT_THICKNESS).abs(),
            };
            let collides = match &chosen {
                None => false,
                Some(None) => true,
                Some(Some(names)) => names.contains(name),
            };
            (name.clone(), member, collides)
        })
        .collect()
}

/// The self-collision members of a built scene of `cloths` and a bound on their candidate
/// pairs (see [`self_collision_pairs`]); zeros without self-collision `sc`.
pub(crate) fn built_pairs(cloths: &[ClothSpec], sc: Option<&SelfCollisionSpec>) -> (u64, u64) {
    let Some(sc) = sc else {
        return (0, 0);
    };
    let members: Vec<Member> = cloths
        .iter()
        .filter(|c| sc.cloths.contains(&c.name))
        .map(|c| Member {
            particles: c.mesh.len() as u64,
            area: c.mesh.area(),
            thickness: c.thickness,
        })
        .collect();
    let count = members.iter().map(|m| m.particles).sum();
    let pairs = contact_pairs(
        &members,
        sc.contact,
        sc.search_margin,
        sc.adaptive_search_margin,
    );
    (count, pairs)
}

/// The memory a built scene of `cloths`, with self-collision `sc`, needs (mesh cloths and
/// garments included; see [`estimate_bytes`]).
pub(crate) fn built_bytes(cloths: &[ClothSpec], sc: Option<&SelfCollisionSpec>) -> u64 {
    let particles: Vec<(Method, u64)> = (cloths.iter())
        .map(|c| (c.method, c.mesh.len() as u64))
        .collect();
    let (members, pairs) = built_pairs(cloths, sc);
    estimate_bytes(&particles, members, pairs)
}

impl Scene {
    /// The memory the scene needs once built and running (the estimate its load checked).
    pub fn estimated_bytes(&self) -> u64 {
        built_bytes(&self.cloths, self.self_collision.as_ref())
    }

    /// The most candidate pairs its self-collision can list (0 without self-collision).
    pub fn self_collision_pair_bound(&self) -> u64 {
        built_pairs(&self.cloths, self.self_collision.as_ref()).1
    }
}

/// `bytes` for people: "3.2 GiB".
pub fn human(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= (1u64 << 30) as f64 {
        format!("{:.1} GiB", b / (1u64 << 30) as f64)
    } else {
        format!("{:.0} MiB", (b / (1u64 << 20) as f64).ceil())
    }
}
