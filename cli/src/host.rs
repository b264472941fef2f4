//! The command line as a job's [`Host`] (and a lab job's [`LabHost`]): opens the GPU (warning loudly when it renders in
//! software although hardware is visible, with a note when no hardware is), prints the input summaries and notes to stderr, and
//! shows progress.

use crate::progress::{Progress, StageProgress};
use std::cell::RefCell;
use viewsynth::gpu::Gpu;
use viewsynth::job::{Event, GpuRequest, Host};
use viewsynth_lab::job::{LabEvent, LabHost};
use viewsynth_lab::progress::Progress as _;

#[derive(Default)]
pub(crate) struct CliHost {
    progress: RefCell<Option<Progress>>,
    stages: RefCell<Option<StageProgress>>,
}

impl Host for CliHost {
    fn open_gpu(&self, request: &GpuRequest) -> viewsynth::Result<Gpu> {
        let gpu = request.open()?;
        let info = gpu.info();
        if let Some(w) = &info.software_warning {
            errln!("\n*** WARNING: {w} ***\n");
        } else if info.software {
            // No hardware visible: not alarming, but never silent (as for Vulkan below).
            errln!("note: OpenGL renders in software ({}): no GPU in use", info.renderer);
        }
        Ok(gpu)
    }

    fn open_vulkan(&self, request: &GpuRequest) -> viewsynth::Result<viewsynth::vulkan::Vk> {
        let vk = request.open_vulkan()?;
        if vk.info().software {
            errln!(
                "note: Vulkan device '{}' renders in software (CPU device)",
                vk.info().name
            );
        }
        Ok(vk)
    }

    fn event(&self, event: Event<'_>) {
        match event {
            Event::InputDepth { path, summary, hint } => {
                errln!("input depth {}: {summary}", path.display());
                for w in summary.warnings() {
                    errln!("warning: {}: {w}; {hint}", path.display());
                }
            }
            Event::InputDisparity { path, summary } => {
                errln!("input disparity {}: {summary}", path.display());
                for w in summary.warnings() {
                    errln!("warning: {}: {w}", path.display());
                }
            }
            Event::DisparityDerived { eye, known_fraction } => {
                let (this, other) = match eye {
                    viewsynth::cyclopean::Eye::Left => ("left", "right"),
                    viewsynth::cyclopean::Eye::Right => ("right", "left"),
                };
                errln!(
                    "note: no --{this}-disparity: the {this} eye's disparity is the {other} one forward-warped \
                     (the nearer surface wins), known at {:.1}% of its pixels; the {this} eye adds colour only \
                     where the {other} eye's geometry says it sees the surface, and what only the {this} eye \
                     sees stays a hole (--fill fills it)",
                    100.0 * known_fraction
                );
            }
            Event::DepthTruncated { limit_m, pixels } => {
                errln!("--depth-trunc {limit_m}: {pixels} pixels beyond {limit_m} m set invalid");
            }
            Event::DisparityRange { min, max, estimated } => {
                let how = if estimated {
                    "estimated from the images"
                } else {
                    "as given"
                };
                errln!("disparity range {min}..{max} px ({how}; --min-disparity/--max-disparity override it)");
            }
            Event::Started { what, total } => *self.progress.borrow_mut() = Some(Progress::new(what, total)),
            Event::Advanced => {
                if let Some(p) = self.progress.borrow().as_ref() {
                    p.inc();
                }
            }
            Event::Finished => {
                if let Some(p) = self.progress.borrow_mut().take() {
                    p.finish();
                }
                if let Some(mut s) = self.stages.borrow_mut().take() {
                    s.finish();
                }
            }
        }
    }
}

impl LabHost for CliHost {
    fn lab_event(&self, event: LabEvent<'_>) {
        match event {
            LabEvent::EmptyDataDir(d) => {
                errln!(
                    "note: --data-dir {} is empty: the real-data rows are skipped",
                    d.display()
                );
            }
            LabEvent::Stage { index, total, label } => self
                .stages
                .borrow_mut()
                .get_or_insert_with(StageProgress::new)
                .stage(index, total, label),
        }
    }
}
