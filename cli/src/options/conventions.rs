//! `--ndc`, `--reversed-z` and `--rows`: the convention switches of a rendering command.

use clap::{Args, ValueEnum};
use viewsynth::convention::{Conventions, NdcDepthRange, RowOrder};

#[derive(Args, Clone, Copy)]
#[command(next_help_heading = super::CONVENTIONS)]
pub(crate) struct ConventionArgs {
    /// NDC depth range of the GPU passes (and of device depth read or written).
    #[arg(long, value_enum, default_value = "gl")]
    ndc: NdcArg,
    /// Reversed-Z: near maps to the top of the depth range and far to 0 (float depth buffer,
    /// cleared to 0, GREATER test); device depth read or written follows it.
    #[arg(long)]
    reversed_z: bool,
    /// Row order of the GPU framebuffers (image files are always written top-down).
    #[arg(long, value_enum, default_value = "bottom-up")]
    rows: RowsArg,
}

impl ConventionArgs {
    /// The switches a request names (`--ndc`, `--reversed-z`) and the pass's row order.
    pub(crate) fn parts(&self) -> (viewsynth::job::stitch::Ndc, bool, RowOrder) {
        let ndc = match self.ndc {
            NdcArg::Gl => viewsynth::job::stitch::Ndc::Gl,
            NdcArg::Vulkan => viewsynth::job::stitch::Ndc::Vulkan,
        };
        (ndc, self.reversed_z, Conventions::from(*self).row_order)
    }
}

impl From<ConventionArgs> for Conventions {
    fn from(a: ConventionArgs) -> Self {
        conventions(a.ndc, a.reversed_z, a.rows)
    }
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum NdcArg {
    /// OpenGL: NDC z in [-1, 1].
    Gl,
    /// Vulkan/D3D: NDC z in [0, 1].
    Vulkan,
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum RowsArg {
    /// OpenGL: row 0 is the bottom of the picture.
    BottomUp,
    /// Vulkan/D3D and image files: row 0 is the top.
    TopDown,
}

/// The conventions the three switches name.
pub(crate) fn conventions(ndc: NdcArg, reversed_z: bool, rows: RowsArg) -> Conventions {
    Conventions {
        ndc_depth: match ndc {
            NdcArg::Gl => NdcDepthRange::MinusOneToOne,
            NdcArg::Vulkan => NdcDepthRange::ZeroToOne,
        },
        reversed_z,
        row_order: match rows {
            RowsArg::BottomUp => RowOrder::BottomUp,
            RowsArg::TopDown => RowOrder::TopDown,
        },
    }
}
