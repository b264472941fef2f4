//! `viewsynth compare`: arguments and the call into viewsynth::compare.

use super::*;

#[derive(Clone, Copy, ValueEnum, PartialEq)]
pub(crate) enum DepthKindArg {
    /// Window depth in [0, 1] from a depth buffer, under the side's conventions.
    Device,
    /// Linear view distance in metres.
    ViewZ,
}

#[derive(Args)]
pub(crate) struct CompareArgs {
    #[arg(long)]
    a_rgb: PathBuf,
    #[arg(long)]
    b_rgb: PathBuf,
    #[arg(long, requires = "b_depth")]
    a_depth: Option<PathBuf>,
    #[arg(long, requires = "a_depth")]
    b_depth: Option<PathBuf>,
    #[arg(long, value_enum, default_value = "view-z")]
    a_depth_kind: DepthKindArg,
    #[arg(long, value_enum, default_value = "view-z")]
    b_depth_kind: DepthKindArg,
    #[arg(long, value_enum, default_value = "gl")]
    a_ndc: NdcArg,
    #[arg(long, value_enum, default_value = "gl")]
    b_ndc: NdcArg,
    #[arg(long)]
    a_reversed_z: bool,
    #[arg(long)]
    b_reversed_z: bool,
    /// Row order each file is stored in (image files are normally top-down).
    #[arg(long, value_enum, default_value = "top-down")]
    a_rows: RowsArg,
    #[arg(long, value_enum, default_value = "top-down")]
    b_rows: RowsArg,
    /// Array of an .npz depth file (both sides) to read (default: the only array, else the first
    /// floating-point one).
    #[arg(long, value_name = "NAME")]
    npz_key: Option<String>,
    /// Near/far planes of the device depth (metres; far may be inf).
    #[arg(long, default_value_t = 0.1)]
    near: f64,
    #[arg(long, default_value_t = 1000.0)]
    far: f64,
    /// Write |A - B| x 8 here.
    #[arg(long)]
    diff: Option<PathBuf>,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

pub(crate) fn compare(a: CompareArgs) -> Result<()> {
    use viewsynth::compare::{compare as run_compare, DepthStorage, Side};
    use viewsynth::convention::DepthPlanes;
    if !(a.near.is_finite() && a.near > 0.0 && a.far > a.near) {
        bail!("invalid --near {} / --far {}: need 0 < near < far", a.near, a.far);
    }
    let planes = DepthPlanes {
        near: a.near,
        far: a.far,
    };
    let side = |rgb: &Path, depth: Option<&Path>, kind: DepthKindArg, conv: Conventions| -> Result<Side> {
        Ok(Side {
            color: io::load_rgb(rgb)?,
            depth: depth
                .map(|d| io::load_depth_with_key(d, a.npz_key.as_deref(), &DepthDecode::default()))
                .transpose()?,
            storage: if kind == DepthKindArg::Device {
                DepthStorage::Device(planes)
            } else {
                DepthStorage::ViewZ
            },
            conv,
        })
    };
    let sa = side(
        &a.a_rgb,
        a.a_depth.as_deref(),
        a.a_depth_kind,
        conventions(a.a_ndc, a.a_reversed_z, a.a_rows),
    )?;
    let sb = side(
        &a.b_rgb,
        a.b_depth.as_deref(),
        a.b_depth_kind,
        conventions(a.b_ndc, a.b_reversed_z, a.b_rows),
    )?;
    let (cmp, diff) = run_compare(&sa, &sb)?;
    if let Some(p) = &a.diff {
        io::save_rgb(p, &diff)?;
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&cmp)?);
    } else {
        println!(
            "colour: PSNR {:.2} dB, max difference {} levels over {} pixels",
            cmp.psnr_db, cmp.max_color_diff, cmp.pixels
        );
        if let (Some(abs), Some(rel), Some(d)) = (cmp.depth_max_abs, cmp.depth_max_rel, cmp.mask_disagreement) {
            println!("depth: max abs {abs:.3e} m, max rel {rel:.3e}; valid in only one: {d} pixels");
        }
        if let Some(s) = &cmp.suspicion {
            println!("suspicion: {s}");
        }
    }
    Ok(())
}
