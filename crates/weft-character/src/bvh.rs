//! A reader of BVH motion capture text (Biovision Hierarchy): HIERARCHY with ROOT, JOINT,
//! End Site, OFFSET and CHANNELS (any order of X/Y/Z position and rotation), then MOTION with
//! `Frames:`, `Frame Time:` and one line of channel values per frame.
//!
//! Conventions (those of the format's common readers, e.g. Blender's): a joint's local
//! transform is T(offset + position channels) · R, where R is the product of the rotation
//! channels in the order listed (`Zrotation Xrotation Yrotation` → R = R_z R_x R_y), angles in
//! degrees. Lengths are multiplied by [`BvhOptions::scale`] (BVH files are often in
//! centimetres or inches). This module parses text; reading files is [`crate::files`]'s job.

use glam::{DQuat, DVec3};

use crate::clip::Clip;
use crate::error::BvhError;
use crate::pose::Pose;
use crate::skeleton::{Joint, Skeleton};

/// The scale that turns the CMU database's BVH conversion (cgspeed.com) into metres: its unit
/// is 1/0.45 inch = 0.056444 m.
pub const CMU_SCALE: f64 = 0.0254 / 0.45;

/// How to read a BVH text.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhOptions {
    /// Factor applied to every offset and position channel (1 for metres, 0.01 for
    /// centimetres, [`CMU_SCALE`] for the CMU conversion).
    pub scale: f64,
}

impl Default for BvhOptions {
    fn default() -> Self {
        Self { scale: 1.0 }
    }
}

/// A coordinate axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    /// x.
    X,
    /// y.
    Y,
    /// z.
    Z,
}

impl Axis {
    fn unit(self) -> DVec3 {
        match self {
            Axis::X => DVec3::X,
            Axis::Y => DVec3::Y,
            Axis::Z => DVec3::Z,
        }
    }
}

/// One BVH channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    /// Translation along an axis (length units of the file).
    Position(Axis),
    /// Rotation about an axis (degrees).
    Rotation(Axis),
}

impl Channel {
    fn parse(name: &str) -> Option<Self> {
        Some(match name {
            "Xposition" => Channel::Position(Axis::X),
            "Yposition" => Channel::Position(Axis::Y),
            "Zposition" => Channel::Position(Axis::Z),
            "Xrotation" => Channel::Rotation(Axis::X),
            "Yrotation" => Channel::Rotation(Axis::Y),
            "Zrotation" => Channel::Rotation(Axis::Z),
            _ => return None,
        })
    }
}

/// A parsed BVH: the skeleton (end sites included, in metres after scaling), the clip and
/// each joint's channels in file order.
#[derive(Clone, Debug)]
pub struct Bvh {
    /// The joint hierarchy.
    pub skeleton: Skeleton,
    /// The motion.
    pub clip: Clip,
    /// Channels of each joint (empty for end sites), in the order the file lists them.
    pub channels: Vec<Vec<Channel>>,
}

/// Deepest joint nesting a BVH file may have below its root. Motion-capture skeletons are
/// under 30 levels deep; the limit keeps a file from driving the parser's recursion into a
/// stack overflow.
pub const MAX_JOINT_DEPTH: usize = 256;

/// Parses BVH text.
pub fn parse_bvh(text: &str, options: &BvhOptions) -> Result<Bvh, BvhError> {
    if !(options.scale.is_finite() && options.scale > 0.0) {
        return Err(BvhError::Scale(options.scale));
    }
    let mut lex = Lexer::new(text);
    lex.expect_word("HIERARCHY", "`HIERARCHY`")?;
    lex.expect_word("ROOT", "`ROOT`")?;
    let mut h = Hierarchy::default();
    h.joint(&mut lex, None, 0, options.scale)?;
    lex.expect_word("MOTION", "`MOTION` after the root joint's closing `}`")?;
    let (frames, frame_time) = motion_header(&mut lex)?;
    let poses = frame_lines(&mut lex, &h.channels, frames, options.scale)?;
    let skeleton = Skeleton::new(h.joints)?;
    let joints = skeleton.len();
    let clip = Clip::new(frame_time, poses, joints)?;
    Ok(Bvh {
        skeleton,
        clip,
        channels: h.channels,
    })
}

/// Joints and channels collected while walking the hierarchy.
#[derive(Default)]
struct Hierarchy {
    joints: Vec<Joint>,
    channels: Vec<Vec<Channel>>,
}

impl Hierarchy {
    /// Reads `name { OFFSET … CHANNELS … children }` after ROOT or JOINT, `depth` levels below
    /// the root (the recursion is bounded by [`MAX_JOINT_DEPTH`], not by the file).
    fn joint(
        &mut self,
        lex: &mut Lexer,
        parent: Option<usize>,
        depth: usize,
        scale: f64,
    ) -> Result<(), BvhError> {
        let (line, name) = lex.name()?;
        if depth > MAX_JOINT_DEPTH {
            return Err(BvhError::TooDeep {
                line,
                limit: MAX_JOINT_DEPTH,
            });
        }
        if self.joints.iter().any(|j| j.name == name) {
            return Err(BvhError::DuplicateJoint { line, name });
        }
        lex.expect_word("{", "`{`")?;
        let index = self.joints.len();
        self.joints.push(Joint {
            name: name.clone(),
            parent,
            offset: DVec3::ZERO,
            end_site: false,
        });
        self.channels.push(Vec::new());
        let mut offset = None;
        let mut channels = None;
        loop {
            let Some((at, word)) = lex.next() else {
                return Err(BvhError::MissingBrace { line, joint: name });
            };
            match word {
                "OFFSET" => offset = Some(lex.vec3()? * scale),
                "CHANNELS" => channels = Some(read_channels(lex, at)?),
                "JOINT" => self.joint(lex, Some(index), depth + 1, scale)?,
                "End" => self.end_site(lex, index, scale)?,
                "}" => break,
                "MOTION" | "ROOT" => return Err(BvhError::MissingBrace { line, joint: name }),
                other => {
                    return Err(BvhError::Expected {
                        line: at,
                        expected: "OFFSET, CHANNELS, JOINT, End Site or `}`",
                        found: other.to_owned(),
                    });
                }
            }
        }
        let Some(offset) = offset else {
            return Err(BvhError::Expected {
                line: lex.line(),
                expected: "an OFFSET before the joint's `}`",
                found: "}".into(),
            });
        };
        self.joints[index].offset = offset;
        self.channels[index] = channels.unwrap_or_default();
        Ok(())
    }

    /// Reads `Site { OFFSET x y z }` after `End`.
    fn end_site(&mut self, lex: &mut Lexer, parent: usize, scale: f64) -> Result<(), BvhError> {
        lex.expect_word("Site", "`Site` after `End`")?;
        let line = lex.line();
        lex.expect_word("{", "`{`")?;
        lex.expect_word("OFFSET", "OFFSET")?;
        let offset = lex.vec3()? * scale;
        let base = format!("{}_End", self.joints[parent].name);
        let mut name = base.clone();
        let mut k = 2;
        while self.joints.iter().any(|j| j.name == name) {
            name = format!("{base}{k}");
            k += 1;
        }
        if !matches!(lex.next(), Some((_, "}"))) {
            return Err(BvhError::MissingBrace { line, joint: name });
        }
        self.joints.push(Joint {
            name,
            parent: Some(parent),
            offset,
            end_site: true,
        });
        self.channels.push(Vec::new());
        Ok(())
    }
}

/// Reads `n name₁ … nameₙ` after CHANNELS; the names must be on the same line.
fn read_channels(lex: &mut Lexer, line: usize) -> Result<Vec<Channel>, BvhError> {
    let n = lex.count("the number of channels")?;
    let names = lex.rest_of_line();
    if names.len() != n {
        return Err(BvhError::Expected {
            line,
            expected: "as many channel names as CHANNELS declares",
            found: format!("{} names for {n} channels", names.len()),
        });
    }
    let mut out: Vec<Channel> = Vec::with_capacity(n);
    for name in names {
        let c = Channel::parse(name).ok_or_else(|| BvhError::UnknownChannel {
            line,
            name: name.to_owned(),
        })?;
        if out.contains(&c) {
            return Err(BvhError::RepeatedChannel {
                line,
                name: name.to_owned(),
            });
        }
        out.push(c);
    }
    Ok(out)
}

/// Reads `Frames: n` and `Frame Time: t`.
fn motion_header(lex: &mut Lexer) -> Result<(usize, f64), BvhError> {
    lex.expect_word("Frames:", "`Frames:`")?;
    let frames_line = lex.line();
    let frames = lex.count("the number of frames")?;
    if frames == 0 {
        return Err(BvhError::ZeroFrames { line: frames_line });
    }
    lex.expect_word("Frame", "`Frame Time:`")?;
    lex.expect_word("Time:", "`Frame Time:`")?;
    let line = lex.line();
    let frame_time = lex.number()?;
    if frame_time <= 0.0 {
        return Err(BvhError::FrameTime {
            line,
            value: frame_time,
        });
    }
    if let Some(&extra) = lex.rest_of_line().first() {
        return Err(BvhError::Expected {
            line,
            expected: "the end of the line after the frame time",
            found: extra.to_owned(),
        });
    }
    Ok((frames, frame_time))
}

/// Reads `frames` lines of channel values (blank lines skipped) into poses.
fn frame_lines(
    lex: &mut Lexer,
    channels: &[Vec<Channel>],
    frames: usize,
    scale: f64,
) -> Result<Vec<Pose>, BvhError> {
    let expected: usize = channels.iter().map(Vec::len).sum();
    // A frame takes a line: the text, not the `Frames:` it declares, bounds the allocation.
    let mut poses = Vec::with_capacity(frames.min(lex.lines_left()));
    let mut values = Vec::with_capacity(expected);
    while poses.len() < frames {
        let Some((line, text)) = lex.next_line() else {
            return Err(BvhError::MissingFrames {
                line: lex.line(),
                found: poses.len(),
                expected: frames,
            });
        };
        values.clear();
        for token in text.split_whitespace() {
            values.push(parse_number(token, line)?);
        }
        if values.is_empty() {
            continue;
        }
        if values.len() != expected {
            return Err(BvhError::FrameValues {
                line,
                frame: poses.len(),
                found: values.len(),
                expected,
            });
        }
        poses.push(pose_from_values(channels, &values, scale));
    }
    while let Some((line, text)) = lex.next_line() {
        if !text.trim().is_empty() {
            return Err(BvhError::ExtraData { line, frames });
        }
    }
    Ok(poses)
}

/// One frame's channel values → local translations and rotations.
fn pose_from_values(channels: &[Vec<Channel>], values: &[f64], scale: f64) -> Pose {
    let mut pose = Pose::identity(channels.len());
    let mut k = 0;
    for (j, list) in channels.iter().enumerate() {
        let mut d = DVec3::ZERO;
        let mut q = DQuat::IDENTITY;
        for c in list {
            let v = values[k];
            k += 1;
            match *c {
                Channel::Position(a) => d += a.unit() * (v * scale),
                Channel::Rotation(a) => q *= DQuat::from_axis_angle(a.unit(), v.to_radians()),
            }
        }
        pose.translations[j] = d;
        pose.rotations[j] = q.normalize();
    }
    pose
}

fn parse_number(token: &str, line: usize) -> Result<f64, BvhError> {
    match token.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(BvhError::NotANumber {
            line,
            token: token.to_owned(),
        }),
    }
}

/// Whitespace tokens with their 1-based line numbers, and whole lines for the frames.
struct Lexer<'a> {
    lines: Vec<&'a str>,
    /// Index of the next line to split.
    next_line: usize,
    /// Tokens left on the current line, in order.
    tokens: std::collections::VecDeque<&'a str>,
    /// 1-based number of the line the last token came from.
    line: usize,
}

impl<'a> Lexer<'a> {
    fn new(text: &'a str) -> Self {
        Self {
            lines: text.lines().collect(),
            next_line: 0,
            tokens: Default::default(),
            line: 1,
        }
    }

    /// Line of the last token read (or the last line of the text at its end).
    fn line(&self) -> usize {
        self.line
    }

    fn next(&mut self) -> Option<(usize, &'a str)> {
        while self.tokens.is_empty() {
            let text = self.lines.get(self.next_line)?;
            self.next_line += 1;
            self.line = self.next_line;
            self.tokens.extend(text.split_whitespace());
        }
        self.tokens.pop_front().map(|t| (self.line, t))
    }

    /// The tokens left on the current line.
    fn rest_of_line(&mut self) -> Vec<&'a str> {
        self.tokens.drain(..).collect()
    }

    /// Lines not yet read (the current line's remaining tokens aside).
    fn lines_left(&self) -> usize {
        self.lines.len() - self.next_line
    }

    /// The next whole line after the current one.
    fn next_line(&mut self) -> Option<(usize, &'a str)> {
        self.tokens.clear();
        let text = self.lines.get(self.next_line)?;
        self.next_line += 1;
        self.line = self.next_line;
        Some((self.line, text))
    }

    fn expect_word(&mut self, word: &str, expected: &'static str) -> Result<(), BvhError> {
        match self.next() {
            Some((_, w)) if w == word => Ok(()),
            Some((line, w)) => Err(BvhError::Expected {
                line,
                expected,
                found: w.to_owned(),
            }),
            None => Err(BvhError::Truncated {
                line: self.line,
                expected,
            }),
        }
    }

    /// A joint name: the rest of the line up to an optional `{` (which is left to be read).
    fn name(&mut self) -> Result<(usize, String), BvhError> {
        let line = match self.next() {
            Some((line, "{")) => {
                return Err(BvhError::Expected {
                    line,
                    expected: "a joint name",
                    found: "{".into(),
                });
            }
            Some((line, first)) => {
                self.tokens.push_front(first);
                line
            }
            None => {
                return Err(BvhError::Truncated {
                    line: self.line,
                    expected: "a joint name",
                });
            }
        };
        let mut parts = Vec::new();
        while let Some(&t) = self.tokens.front() {
            if t == "{" {
                break;
            }
            parts.push(t);
            self.tokens.pop_front();
        }
        Ok((line, parts.join(" ")))
    }

    fn number(&mut self) -> Result<f64, BvhError> {
        match self.next() {
            Some((line, t)) => parse_number(t, line),
            None => Err(BvhError::Truncated {
                line: self.line,
                expected: "a number",
            }),
        }
    }

    fn count(&mut self, expected: &'static str) -> Result<usize, BvhError> {
        match self.next() {
            Some((line, t)) => t.parse::<usize>().map_err(|_| BvhError::NotACount {
                line,
                token: t.to_owned(),
            }),
            None => Err(BvhError::Truncated {
                line: self.line,
                expected,
            }),
        }
    }

    fn vec3(&mut self) -> Result<DVec3, BvhError> {
        Ok(DVec3::new(self.number()?, self.number()?, self.number()?))
    }
}
