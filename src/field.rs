//! The request fields an error can name, and how each front end spells them: the command
//! line's option (`--tau-rel`) and Python's keyword argument (`tau_rel`). Library messages hold
//! [`Field`]s, never flag text ([`Message`]), so each front end renders the same error in its
//! own words and none parses names back out of a message.
//!
//! One table below gives every field its key (the request field's name in
//! `tests/data/front_ends.json`, which `tests/fields.rs` holds it to), its option and its
//! keyword.

use std::borrow::Cow;
use std::fmt;

/// How a front end spells a [`Field`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spelling {
    /// The command line's option, e.g. `--tau-rel`.
    Cli,
    /// Python's keyword argument, e.g. `tau_rel`.
    Python,
}

/// Declares [`Field`] and its table from rows `Variant: "key", "--option", "keyword";`.
macro_rules! fields {
    ($($variant:ident: $key:literal, $cli:literal, $python:literal;)*) => {
        /// A request field a message names, e.g. [`Field::TauRel`]; [`Field::spelled`] writes it
        /// in a front end's words.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[non_exhaustive]
        pub enum Field {
            $(
                #[doc = concat!("`", $cli, "` / `", $python, "`.")]
                $variant,
            )*
        }

        impl Field {
            /// Every field, in table order.
            pub const ALL: &'static [Field] = &[$(Field::$variant),*];

            /// (key, option, keyword) of the field: the one table.
            const fn row(self) -> (&'static str, &'static str, &'static str) {
                match self {
                    $(Field::$variant => ($key, $cli, $python),)*
                }
            }
        }
    };
}

// Keys follow front_ends.json's field names; where an option fills a differently named field
// the key and keyword are that field's (`--zoom-range` fills `scales`, `--force` is the
// opposite of `resume`, `--width-out/--height-out` make `size`), and `from`/`to` are Python
// keywords, so the keywords are `source`/`target`.
fields! {
    ADepth: "a_depth", "--a-depth", "a_depth";
    ADepthKind: "a_depth_kind", "--a-depth-kind", "a_depth_kind";
    AFar: "a_far", "--a-far", "a_far";
    ANdc: "a_ndc", "--a-ndc", "a_ndc";
    ANear: "a_near", "--a-near", "a_near";
    AReversedZ: "a_reversed_z", "--a-reversed-z", "a_reversed_z";
    ARgb: "a_rgb", "--a-rgb", "a_rgb";
    ATransfer: "a_transfer", "--a-transfer", "a_transfer";
    BAlpha: "b_alpha", "--b-alpha", "b_alpha";
    BChannels: "b_channels", "--b-channels", "b_channels";
    BDepth: "b_depth", "--b-depth", "b_depth";
    BDepthKind: "b_depth_kind", "--b-depth-kind", "b_depth_kind";
    BFar: "b_far", "--b-far", "b_far";
    BNdc: "b_ndc", "--b-ndc", "b_ndc";
    BNear: "b_near", "--b-near", "b_near";
    BReversedZ: "b_reversed_z", "--b-reversed-z", "b_reversed_z";
    BRgb: "b_rgb", "--b-rgb", "b_rgb";
    BRows: "b_rows", "--b-rows", "b_rows";
    BTransfer: "b_transfer", "--b-transfer", "b_transfer";
    Backend: "backend", "--backend", "backend";
    BadDepthRel: "bad_depth_rel", "--bad-depth-rel", "bad_depth_rel";
    Baseline: "baseline", "--baseline", "baseline";
    Batch: "batch", "--batch", "batch";
    Blend: "blend", "--blend", "blend";
    Cameras: "cameras", "--cameras", "cameras";
    Color: "color", "--color", "color";
    Confidence: "confidence", "--confidence", "confidence";
    Convergence: "convergence", "--convergence", "convergence";
    CubeFaces: "cube_faces", "--cube-faces", "cube_faces";
    Cx: "cx", "--cx", "cx";
    CxOut: "principal", "--cx-out", "principal";
    Cy: "cy", "--cy", "cy";
    CyOut: "principal", "--cy-out", "principal";
    Depth: "depth", "--depth", "depth";
    DepthFormat: "depth_format", "--depth-format", "depth_format";
    DepthKind: "depth_kind", "--depth-kind", "depth_kind";
    DepthList: "depth_list", "--depth-list", "depth_list";
    DepthPngScale: "depth_png_scale", "--depth-png-scale", "depth_png_scale";
    DepthPreview: "depth_preview", "--depth-preview", "depth_preview";
    DepthScale: "depth_scale", "--depth-scale", "depth_scale";
    DepthTrunc: "depth_trunc", "--depth-trunc", "depth_trunc";
    Device: "device", "--device", "device";
    Diff: "diff", "--diff", "diff";
    DisparityScale: "disparity_scale", "--disparity-scale", "disparity_scale";
    Doffs: "doffs", "--doffs", "doffs";
    Dolly: "dolly", "--dolly", "dolly";
    Dominant: "dominant", "--dominant", "dominant";
    ExrCompression: "exr_compression", "--exr-compression", "exr_compression";
    FaceFov: "face_fov", "--face-fov", "face_fov";
    FaceSize: "face_size", "--face-size", "face_size";
    Faces: "faces", "--faces", "faces";
    Far: "far", "--far", "far";
    Fill: "fill", "--fill", "fill";
    FlipMap: "flip_map", "--flip-map", "flip_map";
    Focal: "focal", "--focal", "focal";
    FocalList: "focal_list", "--focal-list", "focal_list";
    Force: "resume", "--force", "resume";
    Fov: "fov", "--fov", "fov";
    Frames: "frames", "--frames", "frames";
    From: "from", "--from", "source";
    Fx: "fx", "--fx", "fx";
    Fy: "fy", "--fy", "fy";
    Height: "height", "--height", "height";
    HeightOut: "size", "--height-out", "size";
    Intrinsics: "intrinsics", "--intrinsics", "intrinsics";
    Ipd: "ipd", "--ipd", "ipd";
    Jobs: "jobs", "--jobs", "jobs";
    Json: "json", "--json", "json";
    LeftDepth: "left_depth", "--left-depth", "left_depth";
    LeftDisparity: "left_disparity", "--left-disparity", "left_disparity";
    LeftRgb: "left_rgb", "--left-rgb", "left_rgb";
    Mask: "mask", "--mask", "mask";
    Matcher: "matcher", "--matcher", "matcher";
    MaxBadShare: "max_bad_share", "--max-bad-share", "max_bad_share";
    MaxDifference: "max_difference", "--max-difference", "max_difference";
    MaxDisparity: "max_disparity", "--max-disparity", "max_disparity";
    MaxPixels: "max_pixels", "--max-pixels", "max_pixels";
    Method: "method", "--method", "method";
    MinConfidence: "min_confidence", "--min-confidence", "min_confidence";
    MinDisparity: "min_disparity", "--min-disparity", "min_disparity";
    Ndc: "ndc", "--ndc", "ndc";
    Near: "near", "--near", "near";
    NpzKey: "npz_key", "--npz-key", "npz_key";
    Out: "out", "--out", "out";
    OutDir: "out_dir", "--out-dir", "out_dir";
    Outputs: "outputs", "--outputs", "outputs";
    Overlap: "overlap", "--overlap", "overlap";
    PngCompression: "png_compression", "--png-compression", "png_compression";
    PoleFade: "pole_fade", "--pole-fade", "pole_fade";
    Position: "position", "--position", "position";
    RefineSteps: "refine_steps", "--refine-steps", "refine_steps";
    RequireGpu: "require_gpu", "--require-gpu", "require_gpu";
    ReversedZ: "reversed_z", "--reversed-z", "reversed_z";
    Rgb: "rgb", "--rgb", "rgb";
    RgbEverywhere: "rgb_everywhere", "--rgb-everywhere", "rgb_everywhere";
    RgbFormat: "rgb_format", "--rgb-format", "rgb_format";
    RgbList: "rgb_list", "--rgb-list", "rgb_list";
    RightDepth: "right_depth", "--right-depth", "right_depth";
    RightDisparity: "right_disparity", "--right-disparity", "right_disparity";
    RightRgb: "right_rgb", "--right-rgb", "right_rgb";
    Rows: "rows", "--rows", "rows";
    Samples: "samples", "--samples", "samples";
    Scene: "scene", "--scene", "scene";
    Seed: "seed", "--seed", "seed";
    Separation: "separation", "--separation", "separation";
    Sequence: "sequence", "--sequence", "sequence";
    Shard: "shard", "--shard", "shard";
    SpectatorOffset: "spectator_offset", "--spectator-offset", "spectator_offset";
    Steps: "steps", "--steps", "steps";
    SunBitRotate: "sun_bit_rotate", "--sun-bit-rotate", "sun_bit_rotate";
    TauAbs: "tau_abs", "--tau-abs", "tau_abs";
    TauRel: "tau_rel", "--tau-rel", "tau_rel";
    To: "to", "--to", "target";
    Truth: "truth", "--truth", "truth";
    Verify: "verify", "--verify", "verify";
    Width: "width", "--width", "width";
    WidthOut: "size", "--width-out", "size";
    ZThreshold: "z_threshold", "--z-threshold", "z_threshold";
    ZoomRandom: "zoom_random", "--zoom-random", "zoom_random";
    ZoomRange: "scales", "--zoom-range", "scales";
}

impl Field {
    /// The request field's name (front_ends.json's key), e.g. `tau_rel`, `scales`.
    pub const fn key(self) -> &'static str {
        self.row().0
    }

    /// The command line's option, e.g. `--tau-rel`.
    pub const fn cli(self) -> &'static str {
        self.row().1
    }

    /// Python's keyword argument, e.g. `tau_rel`, `source` for `--from`.
    pub const fn python(self) -> &'static str {
        self.row().2
    }

    /// The field as `spelling` writes it.
    pub const fn spelled(self, spelling: Spelling) -> &'static str {
        match spelling {
            Spelling::Cli => self.cli(),
            Spelling::Python => self.python(),
        }
    }
}

impl fmt::Display for Field {
    /// The command line's spelling.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.cli())
    }
}

/// One piece of a [`Message`].
#[derive(Clone, Debug, PartialEq)]
pub enum Part {
    /// Words, the same in every front end.
    Text(Cow<'static, str>),
    /// A field, spelled by the front end.
    Field(Field),
}

/// A message made of text and [`Field`]s, rendered in a front end's spelling
/// ([`Message::spelled`]); `Display` is the command line's. Built with [`msg!`](crate::msg).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Message {
    parts: Vec<Part>,
}

impl Message {
    /// `self` followed by `more`.
    pub fn and(mut self, more: impl Into<Message>) -> Self {
        for part in more.into().parts {
            match (self.parts.last_mut(), part) {
                // Adjacent words stay one part, so a plain message is one text.
                (Some(Part::Text(a)), Part::Text(b)) => a.to_mut().push_str(&b),
                (_, part) => self.parts.push(part),
            }
        }
        self
    }

    /// The message in `spelling`'s words.
    pub fn spelled(&self, spelling: Spelling) -> String {
        let mut out = String::new();
        for part in &self.parts {
            match part {
                Part::Text(t) => out.push_str(t),
                Part::Field(f) => out.push_str(f.spelled(spelling)),
            }
        }
        out
    }

    /// The fields the message names, in order.
    pub fn fields(&self) -> impl Iterator<Item = Field> + '_ {
        self.parts.iter().filter_map(|p| match p {
            Part::Field(f) => Some(*f),
            Part::Text(_) => None,
        })
    }

    /// The parts, in order.
    pub fn parts(&self) -> &[Part] {
        &self.parts
    }

    /// Whether the message is empty.
    pub fn is_empty(&self) -> bool {
        self.parts.is_empty()
    }

    /// Each text part cut by `cut` (a message quoting a huge input stays short).
    pub(crate) fn map_text(self, cut: impl Fn(&str) -> String) -> Self {
        Message {
            parts: self
                .parts
                .into_iter()
                .map(|p| match p {
                    Part::Text(t) => Part::Text(Cow::Owned(cut(&t))),
                    field => field,
                })
                .collect(),
        }
    }
}

impl fmt::Display for Message {
    /// The command line's spelling.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.spelled(Spelling::Cli))
    }
}

impl serde::Serialize for Message {
    /// As the command line's text (reports and `viewsynth info --json` hold it as a string).
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl From<Field> for Message {
    fn from(field: Field) -> Self {
        Message {
            parts: vec![Part::Field(field)],
        }
    }
}

impl From<&str> for Message {
    fn from(text: &str) -> Self {
        Message {
            parts: vec![Part::Text(Cow::Owned(text.to_string()))],
        }
    }
}

impl From<&String> for Message {
    fn from(text: &String) -> Self {
        Message::from(text.as_str())
    }
}

impl From<String> for Message {
    fn from(text: String) -> Self {
        Message {
            parts: vec![Part::Text(Cow::Owned(text))],
        }
    }
}

impl From<&Message> for Message {
    fn from(message: &Message) -> Self {
        message.clone()
    }
}

/// A [`Message`] of the parts given in order: fields, strings and messages,
/// e.g. `msg![Field::Near, "/", Field::Far, " apply to ", Field::DepthKind, " device only"]`.
#[macro_export]
macro_rules! msg {
    ($($part:expr),* $(,)?) => {
        $crate::field::Message::default()$(.and($part))*
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_message_renders_each_front_ends_spelling() {
        let m = msg![
            Field::Near,
            "/",
            Field::Far,
            " apply to ",
            Field::From,
            " ",
            String::from("x")
        ];
        assert_eq!(m.to_string(), "--near/--far apply to --from x");
        assert_eq!(m.spelled(Spelling::Python), "near/far apply to source x");
        assert_eq!(m.fields().collect::<Vec<_>>(), [Field::Near, Field::Far, Field::From]);
    }
}
