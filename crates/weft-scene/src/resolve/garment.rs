//! A garment cloth (`garment = "file"` in a `[cloth.<name>]` table): its panels built into a
//! mesh, its seams, and its attachments to the character's bones.

use weft_character::garment::{GarmentSpec, build_garment};
use weft_solver::glam::DVec3;
use weft_solver::{ClothMesh, Mass};

use super::Checker;
use crate::scene::{AttachSpec, CharacterSpec, ModelSpec};
use crate::schema::ClothSection;

/// Default time over which a garment's seams close (s).
pub(crate) const DEFAULT_SEAM_TIME: f64 = 0.5;

/// Where a garment's attachments find their bones: the scene's skeleton character or its
/// glTF model (whichever resolved), and whether the scene has a `[character]` table at all.
#[derive(Clone, Copy)]
pub(super) struct Rig<'a> {
    pub character: Option<&'a CharacterSpec>,
    pub model: Option<&'a ModelSpec>,
    pub present: bool,
}

impl Rig<'_> {
    /// The bone (skeleton joint index) or glTF joint (node index) named `name`, or why not.
    fn find(&self, name: &str) -> Option<Result<usize, String>> {
        if let Some(m) = self.model {
            let mesh = m.skin.mesh();
            let found = mesh
                .joints
                .iter()
                .copied()
                .find(|&j| mesh.names.get(j).is_some_and(|n| n == name));
            return Some(found.ok_or_else(|| {
                let some: Vec<&str> = mesh
                    .joints
                    .iter()
                    .filter_map(|&j| mesh.names.get(j).map(String::as_str))
                    .take(8)
                    .collect();
                format!(
                    "no joint named `{name}` in the skin of `{}` (its joints include {})",
                    m.path,
                    some.join(", ")
                )
            }));
        }
        let ch = self.character?;
        Some(
            ch.character
                .animation()
                .skeleton()
                .find(name)
                .ok_or_else(|| format!("no bone named `{name}` in the character's skeleton")),
        )
    }
}

/// What a garment file gives a cloth.
pub(super) struct GarmentCloth {
    pub mesh: ClothMesh,
    pub seams: Vec<[u32; 2]>,
    pub attachments: Vec<AttachSpec>,
}

/// Reads and builds the garment of cloth `name` (its `garment` key); `mass` overrides the file's area density
/// when given. `rig` holds the scene's character, if it has one and it resolved.
pub(super) fn garment(
    c: &mut Checker<'_>,
    name: &str,
    s: &ClothSection,
    mass: Option<Mass>,
    center: DVec3,
    rig: Rig<'_>,
) -> Option<GarmentCloth> {
    let k = |field: &str| format!("cloth.{name}.{field}");
    let path = s.garment.as_deref()?;
    let text = c.read_text(&k("garment"), path, "garment")?;
    let built = GarmentSpec::from_toml(&text).and_then(|spec| build_garment(&spec));
    let g = match built {
        Ok(g) => g,
        Err(e) => {
            c.bad(&k("garment"), format!("bad garment `{path}`: {e}"));
            return None;
        }
    };
    let mut attachments = Vec::new();
    let list = s.attach.as_deref().unwrap_or_default();
    if !list.is_empty() && !rig.present {
        c.bad(
            &k("attach"),
            "attachments need a [character] table whose bones they follow",
        );
    }
    for (i, a) in list.iter().enumerate() {
        let ak = |field: &str| format!("cloth.{name}.attach[{i}].{field}");
        let bone = match rig.find(&a.bone) {
            Some(Ok(b)) => Some(b),
            Some(Err(message)) => {
                c.bad(&ak("bone"), message);
                None
            }
            None => None,
        };
        let Some(panel) = g.panel(&a.panel) else {
            let names: Vec<&str> = g.panels.iter().map(|p| p.name.as_str()).collect();
            c.bad(
                &ak("panel"),
                format!(
                    "no panel named `{}` in `{path}` (its panels: {})",
                    a.panel,
                    names.join(", ")
                ),
            );
            continue;
        };
        let m = panel.edge_starts.len();
        let [first, last] = a.edges;
        let in_range = |e: i64| e >= 0 && (e as usize) < m;
        if !in_range(first) || !in_range(last) {
            c.bad(
                &ak("edges"),
                format!(
                    "panel `{}` has edges 0..={}, got [{first}, {last}]",
                    a.panel,
                    m - 1
                ),
            );
            continue;
        }
        let [from, to] = a.span.unwrap_or([0.0, 1.0]);
        if !(from.is_finite() && to.is_finite() && 0.0 <= from && from <= to && to <= 1.0) {
            c.bad(
                &ak("span"),
                format!("must be two fractions 0 <= from <= to <= 1, got [{from}, {to}]"),
            );
            continue;
        }
        let run = panel
            .edge_run(first as usize, last as usize)
            .unwrap_or_default();
        let n = run.len().saturating_sub(1).max(1) as f64;
        let vertices: Vec<u32> = run
            .iter()
            .enumerate()
            .filter(|&(j, _)| {
                let f = j as f64 / n;
                f >= from - 1e-12 && f <= to + 1e-12
            })
            .map(|(_, &v)| v)
            .collect();
        if vertices.is_empty() {
            c.bad(&ak("span"), "selects no vertex");
            continue;
        }
        if let Some(bone) = bone {
            attachments.push(AttachSpec {
                bone,
                bone_name: a.bone.clone(),
                vertices,
            });
        }
    }
    let positions: Vec<DVec3> = g.mesh.positions.iter().map(|p| *p + center).collect();
    let mesh = match mass {
        Some(mass) => ClothMesh::from_triangles(positions, g.mesh.triangles.clone(), mass, vec![]),
        None => {
            let mut mesh = g.mesh.clone();
            mesh.positions = positions;
            Ok(mesh)
        }
    };
    match mesh {
        Ok(mesh) => Some(GarmentCloth {
            mesh,
            seams: g.seam_pairs.clone(),
            attachments,
        }),
        Err(e) => {
            c.bad(&k("garment"), format!("bad garment `{path}`: {e}"));
            None
        }
    }
}
