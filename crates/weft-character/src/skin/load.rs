//! From a parsed glTF document and its buffers to a [`SkinnedMesh`].

use base64::Engine;
use glam::{DMat4, DQuat, DVec3};
use gltf::animation::util::ReadOutputs;
use gltf::mesh::Mode;

use super::animation::{Channel, ChannelValues, Interpolation};
use super::{NodeRest, SkinError, SkinnedMesh};

/// Where a buffer's bytes are.
#[derive(Clone, Debug, PartialEq)]
pub enum BufferSource {
    /// Embedded (the GLB binary chunk or a `data:` URI), decoded.
    Data(Vec<u8>),
    /// A URI relative to the file, for the caller to read.
    External(String),
}

/// Which of a document's animations a skinned mesh plays.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum AnimationChoice {
    /// The first, if there is one (none: the rest pose).
    #[default]
    First,
    /// The one at this index.
    Index(usize),
    /// The one with this name.
    Name(String),
}

impl AnimationChoice {
    /// The chosen animation of `doc`; an index or name it does not have is an error that
    /// lists the animations it has.
    pub fn pick<'a>(
        &self,
        doc: &'a gltf::Document,
    ) -> Result<Option<gltf::Animation<'a>>, SkinError> {
        let found = match self {
            Self::First => return Ok(doc.animations().next()),
            Self::Index(i) => doc.animations().nth(*i),
            Self::Name(n) => doc.animations().find(|a| a.name() == Some(n.as_str())),
        };
        found.map(Some).ok_or_else(|| {
            let names: Vec<String> = doc
                .animations()
                .map(|a| format!("{} `{}`", a.index(), a.name().unwrap_or_default()))
                .collect();
            let what = match self {
                Self::Index(i) => format!("no animation {i}"),
                Self::Name(n) => format!("no animation named `{n}`"),
                Self::First => "no animation".to_owned(),
            };
            SkinError::NoSuchAnimation(format!(
                "{what} (the file's animations: {})",
                if names.is_empty() {
                    "none".to_owned()
                } else {
                    names.join(", ")
                }
            ))
        })
    }
}

/// Parses `.gltf` (JSON) or `.glb` bytes; embedded buffers are decoded, external ones named.
pub fn parse_gltf_slice(bytes: &[u8]) -> Result<(gltf::Document, Vec<BufferSource>), SkinError> {
    let gltf = gltf::Gltf::from_slice(bytes).map_err(|e| SkinError::Gltf(e.to_string()))?;
    let mut blob = gltf.blob.clone();
    let sources = gltf
        .document
        .buffers()
        .map(|b| match b.source() {
            gltf::buffer::Source::Bin => {
                blob.take()
                    .map(BufferSource::Data)
                    .ok_or_else(|| SkinError::Buffer {
                        index: b.index(),
                        message: "refers to a binary chunk the file does not have".into(),
                    })
            }
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => decode_data_uri(uri)
                .map(BufferSource::Data)
                .map_err(|message| SkinError::Buffer {
                    index: b.index(),
                    message,
                }),
            gltf::buffer::Source::Uri(uri) => Ok(BufferSource::External(uri.to_owned())),
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((gltf.document, sources))
}

/// Decodes a base64 `data:` URI (`data:[type];base64,<payload>`).
pub fn decode_data_uri(uri: &str) -> Result<Vec<u8>, String> {
    let (head, payload) = uri
        .split_once(',')
        .ok_or_else(|| "a data URI without a comma".to_owned())?;
    if !head.ends_with(";base64") {
        return Err(format!("data URI `{head}` is not base64"));
    }
    base64::engine::general_purpose::STANDARD
        .decode(payload)
        .map_err(|e| format!("bad base64: {e}"))
}

fn vec3(v: [f32; 3]) -> DVec3 {
    DVec3::new(v[0].into(), v[1].into(), v[2].into())
}

fn quat(v: [f32; 4]) -> DQuat {
    DQuat::from_xyzw(v[0].into(), v[1].into(), v[2].into(), v[3].into()).normalize()
}

impl SkinnedMesh {
    /// Reads every node's rest transform and name, the skin of the first node that has both
    /// a mesh and a skin, the meshes of every node skinned by that skin (their primitives
    /// joined into one mesh, as one character split into body, head and legs is), and the
    /// first animation; `buffers` holds the document's buffers in order.
    pub fn from_document(doc: &gltf::Document, buffers: &[Vec<u8>]) -> Result<Self, SkinError> {
        Self::from_document_with(doc, buffers, &AnimationChoice::First)
    }

    /// [`Self::from_document`] playing the animation `animation` chooses.
    pub fn from_document_with(
        doc: &gltf::Document,
        buffers: &[Vec<u8>],
        animation: &AnimationChoice,
    ) -> Result<Self, SkinError> {
        if buffers.len() < doc.buffers().count() {
            return Err(SkinError::Invalid(format!(
                "{} buffers given for {}",
                buffers.len(),
                doc.buffers().count()
            )));
        }
        check_channels(doc)?;
        check_accessors(doc, buffers)?;
        let get = |b: gltf::Buffer| buffers.get(b.index()).map(Vec::as_slice);
        let (nodes, order) = node_tree(doc)?;
        let skin = doc
            .nodes()
            .find_map(|n| n.mesh().and(n.skin()))
            .ok_or(SkinError::NoSkinnedMesh)?;
        let meshes: Vec<gltf::Mesh> = doc
            .nodes()
            .filter(|n| n.skin().is_some_and(|s| s.index() == skin.index()))
            .filter_map(|n| n.mesh())
            .collect();
        let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
        let inverse_bind: Vec<DMat4> = match skin.reader(get).read_inverse_bind_matrices() {
            Some(m) => m
                .map(|c| DMat4::from_cols_array_2d(&c.map(|col| col.map(f64::from))))
                .collect(),
            None => vec![DMat4::IDENTITY; joints.len()],
        };
        if !inverse_bind.iter().all(|m| m.is_finite()) {
            return Err(SkinError::Invalid(
                "an inverse bind matrix is not finite".into(),
            ));
        }
        if inverse_bind.len() != joints.len() {
            return Err(SkinError::Invalid(format!(
                "{} inverse bind matrices for {} joints",
                inverse_bind.len(),
                joints.len()
            )));
        }
        let mut out = SkinnedMesh {
            nodes,
            order,
            names: doc
                .nodes()
                .map(|n| n.name().unwrap_or_default().to_owned())
                .collect(),
            joints,
            inverse_bind,
            positions: Vec::new(),
            triangles: Vec::new(),
            influences: Vec::new(),
            channels: Vec::new(),
        };
        for mesh in &meshes {
            for prim in mesh.primitives() {
                out.add_primitive(mesh.index(), &prim, get)?;
            }
        }
        if let Some(anim) = animation.pick(doc)? {
            for ch in anim.channels() {
                if let Some(c) = read_channel(&ch, get)? {
                    out.channels.push(c);
                }
            }
        }
        Ok(out)
    }

    fn add_primitive<'a, 's, F>(
        &mut self,
        mesh: usize,
        prim: &'a gltf::Primitive<'a>,
        get: F,
    ) -> Result<(), SkinError>
    where
        F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
    {
        let primitive = prim.index();
        let missing = |attribute| SkinError::MissingAttribute {
            mesh,
            primitive,
            attribute,
        };
        if prim.mode() != Mode::Triangles {
            return Err(SkinError::Unsupported(format!(
                "mesh {mesh}, primitive {primitive}: mode {:?} (only triangles)",
                prim.mode()
            )));
        }
        let reader = prim.reader(get);
        let positions: Vec<DVec3> = reader
            .read_positions()
            .ok_or_else(|| missing("POSITION"))?
            .map(vec3)
            .collect();
        let joints: Vec<[u16; 4]> = reader
            .read_joints(0)
            .ok_or_else(|| missing("JOINTS_0"))?
            .into_u16()
            .collect();
        let weights: Vec<[f32; 4]> = reader
            .read_weights(0)
            .ok_or_else(|| missing("WEIGHTS_0"))?
            .into_f32()
            .collect();
        let n = positions.len();
        if let Some(k) = positions.iter().position(|p| !p.is_finite()) {
            return Err(SkinError::Invalid(format!(
                "mesh {mesh}, primitive {primitive}: vertex {k} is not finite"
            )));
        }
        if joints.len() != n || weights.len() != n {
            return Err(SkinError::Invalid(format!(
                "mesh {mesh}, primitive {primitive}: {n} positions, {} joints, {} weights",
                joints.len(),
                weights.len()
            )));
        }
        let base = self.positions.len() as u32;
        for (k, (j, w)) in joints.iter().zip(&weights).enumerate() {
            let w = w.map(f64::from);
            let sum: f64 = w.iter().sum();
            let bad_joint = j
                .iter()
                .zip(&w)
                .any(|(&j, &w)| w != 0.0 && j as usize >= self.joints.len());
            if w.iter().any(|x| !x.is_finite() || *x < 0.0) || sum <= 0.0 || bad_joint {
                return Err(SkinError::Invalid(format!(
                    "mesh {mesh}, primitive {primitive}, vertex {k}: weights {w:?} on joints {j:?}"
                )));
            }
            self.influences
                .push(std::array::from_fn(|i| (j[i], w[i] / sum)));
        }
        let indices: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..n as u32).collect(),
        };
        if indices.len() % 3 != 0 || indices.iter().any(|&i| i as usize >= n) {
            return Err(SkinError::Invalid(format!(
                "mesh {mesh}, primitive {primitive}: indices out of range or not triangles"
            )));
        }
        self.triangles.extend(
            indices
                .chunks_exact(3)
                .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
        );
        self.positions.extend(positions);
        Ok(())
    }
}

/// Rest transforms and parents of every node, and an order with parents first.
fn node_tree(doc: &gltf::Document) -> Result<(Vec<NodeRest>, Vec<usize>), SkinError> {
    let mut nodes: Vec<NodeRest> = doc
        .nodes()
        .map(|n| {
            let (t, r, s) = n.transform().decomposed();
            NodeRest {
                parent: None,
                translation: vec3(t),
                rotation: quat(r),
                scale: vec3(s),
            }
        })
        .collect();
    for n in doc.nodes() {
        for c in n.children() {
            if nodes[c.index()].parent.is_some() {
                return Err(SkinError::Invalid(format!(
                    "node {} has two parents",
                    c.index()
                )));
            }
            nodes[c.index()].parent = Some(n.index());
        }
    }
    let mut order: Vec<usize> = (0..nodes.len())
        .filter(|&i| nodes[i].parent.is_none())
        .collect();
    let mut k = 0;
    while k < order.len() {
        let p = order[k];
        order.extend((0..nodes.len()).filter(|&i| nodes[i].parent == Some(p)));
        k += 1;
    }
    if order.len() != nodes.len() {
        return Err(SkinError::Invalid("the node hierarchy has a cycle".into()));
    }
    Ok((nodes, order))
}

/// Refuses animation channels whose target the gltf crate leaves unchecked (its
/// `Target::property` and `Target::node` panic on them): an unknown property name, or a node
/// index past the file's nodes.
fn check_channels(doc: &gltf::Document) -> Result<(), SkinError> {
    let json = doc.as_json();
    for (a, animation) in json.animations.iter().enumerate() {
        for (c, channel) in animation.channels.iter().enumerate() {
            let target = &channel.target;
            let problem = if !matches!(target.path, gltf::json::validation::Checked::Valid(_)) {
                "its target property is not translation, rotation, scale or weights".to_owned()
            } else if target.node.value() >= json.nodes.len() {
                format!(
                    "its target node {} is past the file's {} nodes",
                    target.node.value(),
                    json.nodes.len()
                )
            } else {
                continue;
            };
            return Err(SkinError::Invalid(format!(
                "animation {a}, channel {c}: {problem}"
            )));
        }
    }
    Ok(())
}

/// Refuses accessors the gltf crate's readers would index out of range or overflow on (with
/// overflow checks on, a panic): no elements, a stride shorter than an element, or elements
/// that reach past their buffer view, or a view past its buffer.
fn check_accessors(doc: &gltf::Document, buffers: &[Vec<u8>]) -> Result<(), SkinError> {
    for a in doc.accessors() {
        let Some(view) = a.view() else { continue };
        let (count, size) = (a.count(), a.size());
        let stride = view.stride().unwrap_or(size);
        let end = count
            .checked_sub(1)
            .and_then(|last| last.checked_mul(stride))
            .and_then(|x| x.checked_add(size))
            .and_then(|x| x.checked_add(a.offset()));
        let buffer = buffers.get(view.buffer().index()).map_or(0, Vec::len);
        let view_end = view.offset().checked_add(view.length());
        let problem = if count == 0 {
            "has no elements".to_owned()
        } else if stride < size {
            format!("has a stride of {stride} bytes for {size}-byte elements")
        } else if end.is_none_or(|e| e > view.length()) {
            format!(
                "holds {count} elements of {size} bytes, past its buffer view's {} bytes",
                view.length()
            )
        } else if view_end.is_none_or(|e| e > buffer) {
            format!("reads a buffer view past its buffer's {buffer} bytes")
        } else {
            continue;
        };
        return Err(SkinError::Invalid(format!(
            "accessor {} {problem}",
            a.index()
        )));
    }
    Ok(())
}

fn read_channel<'a, 's, F>(
    ch: &gltf::animation::Channel<'a>,
    get: F,
) -> Result<Option<Channel>, SkinError>
where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    let interpolation = match ch.sampler().interpolation() {
        gltf::animation::Interpolation::Linear => Interpolation::Linear,
        gltf::animation::Interpolation::Step => Interpolation::Step,
        gltf::animation::Interpolation::CubicSpline => {
            return Err(SkinError::Unsupported(format!(
                "animation channel {}: cubic-spline interpolation",
                ch.index()
            )));
        }
    };
    let reader = ch.reader(get);
    let times: Vec<f64> = reader
        .read_inputs()
        .ok_or_else(|| SkinError::Invalid(format!("channel {}: no key times", ch.index())))?
        .map(f64::from)
        .collect();
    let values = match reader.read_outputs() {
        Some(ReadOutputs::Translations(v)) => ChannelValues::Translation(v.map(vec3).collect()),
        Some(ReadOutputs::Rotations(v)) => {
            ChannelValues::Rotation(v.into_f32().map(quat).collect())
        }
        Some(ReadOutputs::Scales(v)) => ChannelValues::Scale(v.map(vec3).collect()),
        Some(ReadOutputs::MorphTargetWeights(_)) => return Ok(None),
        None => {
            return Err(SkinError::Invalid(format!(
                "channel {}: no key values",
                ch.index()
            )));
        }
    };
    let count = match &values {
        ChannelValues::Translation(v) | ChannelValues::Scale(v) => v.len(),
        ChannelValues::Rotation(v) => v.len(),
    };
    let finite = match &values {
        ChannelValues::Translation(v) | ChannelValues::Scale(v) => v.iter().all(|x| x.is_finite()),
        ChannelValues::Rotation(v) => v.iter().all(|q| q.is_finite()),
    };
    if !finite {
        return Err(SkinError::Invalid(format!(
            "channel {}: a key value is not finite",
            ch.index()
        )));
    }
    let bad_times = times.iter().any(|t| !t.is_finite()) || times.windows(2).any(|w| w[1] <= w[0]);
    if count != times.len() || bad_times {
        return Err(SkinError::Invalid(format!(
            "channel {}: {} times for {count} values, or times not increasing",
            ch.index(),
            times.len()
        )));
    }
    Ok(Some(Channel {
        node: ch.target().node().index(),
        times,
        values,
        interpolation,
    }))
}
