//! Assembles cloths, their constraints and kinematic pins into a [`Solver`].

use glam::DVec3;

use crate::cloth::ClothMesh;
use crate::constraints::{
    Block, BlockBuilder, ConstraintSet, Dihedral, Distance, Isometric, Seam, Shape, Tether,
};
use crate::error::{BuildError, ParamError};
use crate::forces::Forces;
use crate::motion::{KinematicPin, Motion};
use crate::params::{ClothParams, Direction, Family, FamilyParams, check_thickness};
use crate::particles::Particles;
use crate::settings::Settings;
use crate::solver::{Cloth, Solver};
use crate::topology::Topology;

/// Collects cloths and pins, then colours the constraints and yields a [`Solver`].
///
/// A family disabled when its cloth is added gets no constraints; enabling it later needs a
/// rebuild. A family disabled later is skipped at run time.
#[derive(Debug)]
pub struct SolverBuilder {
    settings: Settings,
    forces: Forces,
    particles: Particles,
    cloths: Vec<Cloth>,
    params: Vec<ClothParams>,
    distance: BlockBuilder<2, Distance>,
    dihedral: BlockBuilder<4, Dihedral>,
    isometric: BlockBuilder<4, Isometric>,
    tethers: BlockBuilder<2, Tether>,
    seams: BlockBuilder<2, Seam>,
    seam_params: Vec<FamilyParams>,
    pins: Vec<KinematicPin>,
}

/// A builder's parts once its constraint blocks are finished.
struct Finished {
    constraints: ConstraintSet,
    settings: Settings,
    forces: Forces,
    particles: Particles,
    cloths: Vec<Cloth>,
    params: Vec<ClothParams>,
    pins: Vec<KinematicPin>,
}

impl SolverBuilder {
    /// Starts a solver with validated settings and forces.
    pub fn new(settings: Settings, forces: Forces) -> Result<Self, ParamError> {
        settings.validate()?;
        forces.validate()?;
        Ok(Self {
            settings,
            forces,
            particles: Particles::default(),
            cloths: Vec::new(),
            params: Vec::new(),
            distance: BlockBuilder::default(),
            dihedral: BlockBuilder::default(),
            isometric: BlockBuilder::default(),
            tethers: BlockBuilder::default(),
            seams: BlockBuilder::default(),
            seam_params: Vec::new(),
            pins: Vec::new(),
        })
    }

    /// Adds a cloth with its family parameters and thickness (m); returns its index.
    pub fn add_cloth(
        &mut self,
        name: impl Into<String>,
        mesh: &ClothMesh,
        params: ClothParams,
        thickness: f64,
    ) -> Result<usize, BuildError> {
        let topology = Topology::new(&mesh.triangles);
        self.add_cloth_with_topology(name, mesh, &topology, params, thickness)
    }

    /// [`add_cloth`](Self::add_cloth) with the mesh's topology already built
    /// (`Topology::new(&mesh.triangles)`): a loader that also worked out the spring defaults
    /// builds it once for both (a second of a million-particle cloth's load).
    pub fn add_cloth_with_topology(
        &mut self,
        name: impl Into<String>,
        mesh: &ClothMesh,
        topo: &Topology,
        params: ClothParams,
        thickness: f64,
    ) -> Result<usize, BuildError> {
        let name = name.into();
        params.validate()?;
        check_thickness(thickness)?;
        if mesh.masses.len() != mesh.positions.len() {
            return Err(BuildError::MassCount {
                name,
                positions: mesh.positions.len(),
                masses: mesh.masses.len(),
            });
        }
        let cloth = self.cloths.len();
        let offset = self.particles.len() as u32;
        let start = self.particles.len();
        let mut pinned = vec![false; mesh.len()];
        for &p in &mesh.pinned {
            pinned[p as usize] = true;
        }
        for (i, (&x, &m)) in mesh.positions.iter().zip(&mesh.masses).enumerate() {
            let w = if pinned[i] || m <= 0.0 { 0.0 } else { 1.0 / m };
            self.particles.push(x, w);
        }
        // A stretch edge acts along itself; a hinge bends the cloth across its edge.
        let along = |a: u32, b: u32| grid_direction(mesh.grid, a, b);
        let across = |a: u32, b: u32| match along(a, b) {
            Direction::Warp => Direction::Weft,
            Direction::Weft => Direction::Warp,
            Direction::Bias => Direction::Bias,
        };
        let group = |f: Family, d: Direction| ClothParams::group(cloth, f, d);
        self.params.push(params);
        let g = |i: u32| i + offset;
        let p = &mesh.positions;
        let dist = |a: u32, b: u32| p[a as usize].distance(p[b as usize]);
        for (family, pairs) in [
            (Family::Stretch, &mesh.stretch),
            (Family::Shear, &mesh.shear),
        ] {
            if params.get(family).enabled {
                for &[a, b] in pairs {
                    self.distance.push(
                        [g(a), g(b)],
                        group(family, along(a, b)),
                        Distance { rest: dist(a, b) },
                    );
                }
            }
        }
        if params.get(Family::BendDistance).enabled {
            // Two edges can share a wing pair (on a grid with alternating diagonals, the pair
            // two apart across a vertex); each pair gets one constraint, not one per edge.
            let mut pairs: Vec<(u32, u32)> = topo
                .wings
                .iter()
                .map(|w| (w.wing_a.min(w.wing_b), w.wing_a.max(w.wing_b)))
                .collect();
            pairs.sort_unstable();
            pairs.dedup();
            for (a, b) in pairs {
                self.distance.push(
                    [g(a), g(b)],
                    group(Family::BendDistance, Direction::Bias),
                    Distance { rest: dist(a, b) },
                );
            }
        }
        if params.get(Family::BendDihedral).enabled {
            for wing in &topo.wings {
                let idx = [wing.wing_a, wing.wing_b, wing.edge[0], wing.edge[1]];
                if let Some(rest) = Dihedral::angle(&idx.map(|i| p[i as usize])) {
                    let d = across(wing.edge[0], wing.edge[1]);
                    self.dihedral.push(
                        idx.map(g),
                        group(Family::BendDihedral, d),
                        Dihedral { rest },
                    );
                }
            }
        }
        if params.get(Family::BendIsometric).enabled {
            for wing in &topo.wings {
                let idx = [wing.wing_a, wing.wing_b, wing.edge[0], wing.edge[1]];
                if let Some(shape) = Isometric::at_rest(&idx.map(|i| p[i as usize])) {
                    let d = across(wing.edge[0], wing.edge[1]);
                    self.isometric
                        .push(idx.map(g), group(Family::BendIsometric, d), shape);
                }
            }
        }
        if params.get(Family::Tether).enabled && !mesh.pinned.is_empty() {
            for i in (0..mesh.len() as u32).filter(|&i| !pinned[i as usize]) {
                let nearest = mesh
                    .pinned
                    .iter()
                    .copied()
                    .min_by(|&a, &b| dist(i, a).total_cmp(&dist(i, b)));
                if let Some(anchor) = nearest {
                    self.tethers.push(
                        [g(i), g(anchor)],
                        group(Family::Tether, Direction::Warp),
                        Tether {
                            max_length: dist(i, anchor),
                        },
                    );
                }
            }
        }
        self.cloths.push(Cloth {
            name,
            particles: start..self.particles.len(),
            triangles: mesh.triangles.iter().map(|t| t.map(g)).collect(),
            edges: mesh.stretch.iter().map(|e| e.map(g)).collect(),
            thickness,
            grid: mesh.grid,
        });
        Ok(cloth)
    }

    /// Sews vertex pairs `pairs` of cloth `cloth` (vertex indices in its mesh): each pair gets
    /// a [`Seam`] whose rest length ramps from the pair's present distance to zero over
    /// `closing_time` seconds (from the solver's time 0), then holds it closed. `params` says
    /// how stiff the seams are for each method (XPBD compliance and damping, PBD stiffness,
    /// mass-spring stiffness and damping); returns the index of this set of seams.
    pub fn add_seams(
        &mut self,
        cloth: usize,
        pairs: &[[u32; 2]],
        closing_time: f64,
        params: FamilyParams,
    ) -> Result<usize, BuildError> {
        let range = self
            .cloths
            .get(cloth)
            .map(|c| c.particles.clone())
            .ok_or(BuildError::NoSuchVertex { cloth, vertex: 0 })?;
        if !(closing_time.is_finite() && closing_time >= 0.0) {
            return Err(ParamError {
                name: "seam.closing_time".into(),
                value: closing_time,
                expected: "finite and >= 0",
            }
            .into());
        }
        params.validate_as("seam")?;
        let group = self.seam_params.len() as u32;
        for &[a, b] in pairs {
            for v in [a, b] {
                if range.start + v as usize >= range.end {
                    return Err(BuildError::NoSuchVertex { cloth, vertex: v });
                }
            }
            let (i, j) = (range.start + a as usize, range.start + b as usize);
            let gap = self.particles.positions[i].distance(self.particles.positions[j]);
            self.seams
                .push([i as u32, j as u32], group, Seam::new(gap, closing_time));
        }
        self.seam_params.push(params);
        Ok(group as usize)
    }

    /// Pins vertex `vertex` of cloth `cloth` (inverse mass 0) to follow `motion` from its rest position.
    pub fn add_kinematic_pin(
        &mut self,
        cloth: usize,
        vertex: u32,
        motion: Motion,
    ) -> Result<(), BuildError> {
        let range = self
            .cloths
            .get(cloth)
            .map(|c| c.particles.clone())
            .ok_or(BuildError::NoSuchVertex { cloth, vertex })?;
        let particle = range.start + vertex as usize;
        if particle >= range.end {
            return Err(BuildError::NoSuchVertex { cloth, vertex });
        }
        self.particles.inv_masses[particle] = 0.0;
        self.pins.push(KinematicPin {
            particle: particle as u32,
            rest: self.particles.positions[particle],
            motion,
        });
        Ok(())
    }

    /// Colours the constraints and returns the solver.
    pub fn build(self) -> Solver {
        let p = self.finish(true);
        let n = p.particles.len();
        Solver::assemble(
            p.settings,
            p.forces,
            p.particles,
            p.cloths,
            p.params,
            p.constraints,
            p.pins,
            vec![DVec3::ZERO; n],
        )
    }

    /// Gershgorin's bound on the springs' ω of cloth `cloth` (see
    /// [`StabilityBound`](crate::StabilityBound)) from what was added, without building a
    /// solver: its domains cost many times the bound.
    pub(crate) fn spring_omega(self, cloth: usize) -> f64 {
        let p = self.finish(false);
        p.cloths.get(cloth).map_or(0.0, |c| {
            crate::stability::bound(
                &p.constraints,
                &p.particles.positions,
                &p.particles.inv_masses,
                &crate::params::expand(&p.params, p.settings.iterations),
                c.particles.clone(),
                false,
            )
            .omega
        })
    }

    /// What the solver is assembled from, its constraint blocks finished: coloured for the
    /// solver's sweeps when `ordered`, as added otherwise.
    fn finish(self, ordered: bool) -> Finished {
        let free: Vec<bool> = self.particles.inv_masses.iter().map(|&w| w > 0.0).collect();
        fn block<const N: usize, S: Shape<N>>(
            b: BlockBuilder<N, S>,
            free: &[bool],
            ordered: bool,
        ) -> Block<N, S> {
            if ordered {
                b.finish(free)
            } else {
                b.unordered()
            }
        }
        Finished {
            constraints: ConstraintSet {
                distance: block(self.distance, &free, ordered),
                dihedral: block(self.dihedral, &free, ordered),
                isometric: block(self.isometric, &free, ordered),
                tethers: block(self.tethers, &free, ordered),
                seams: block(self.seams, &free, ordered),
                seam_params: self.seam_params,
                isometric_forward: false,
                isometric_constants: Default::default(),
                xpbd_h: 0.0,
                plan: Default::default(),
                cg: Default::default(),
            },
            settings: self.settings,
            forces: self.forces,
            particles: self.particles,
            cloths: self.cloths,
            params: self.params,
            pins: self.pins,
        }
    }
}

/// The direction of the edge `a`–`b` on a cloth with grid `grid` (vertex `j · columns + i`),
/// [`Direction::Bias`] on a cloth without one.
fn grid_direction(grid: Option<(usize, usize)>, a: u32, b: u32) -> Direction {
    let Some((columns, _)) = grid else {
        return Direction::Bias;
    };
    let at = |v: u32| (v as usize % columns, v as usize / columns);
    let ((ia, ja), (ib, jb)) = (at(a), at(b));
    if ja == jb {
        Direction::Warp
    } else if ia == ib {
        Direction::Weft
    } else {
        Direction::Bias
    }
}
