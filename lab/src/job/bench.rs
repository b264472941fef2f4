//! `bench`: median timings of refocus (both GPU paths), cyclopean and stitch, or with
//! `--batch` the pipelined refocus batch against its synchronous baseline. The options become a
//! [`BenchJob`]; running it returns the tables and the cases measured.

use super::{ArgError, HostStages, JobError, LabHost};
use crate::bench::batch::{batch_bench, BatchBench, BatchInput};
use crate::bench::{cyclopean_bench, refocus_bench, BenchCase};
use crate::progress::Progress as _;
use std::path::PathBuf;
use viewsynth::io;
use viewsynth::io::FileFormats;
use viewsynth::job::{Event, GpuRequest};

/// The bench options as given.
#[derive(Debug, Clone)]
pub struct BenchOptions {
    /// Sizes `WxH` to measure.
    pub sizes: Vec<String>,
    /// Repetitions per measurement.
    pub repeats: usize,
    /// `N` frames of the built-in scene or a manifest file: the batch benchmark.
    pub batch: Option<String>,
    /// Batch: threads per CPU pool (None: the number of cores).
    pub jobs: Option<usize>,
    /// Batch: PNG compression.
    pub png_compression: String,
    /// The GPU to render on.
    pub gpu: GpuRequest,
    /// Also time refocus on the Vulkan device `--device auto` opens.
    pub with_vulkan: bool,
}

/// What to measure.
#[derive(Debug, Clone)]
enum Bench {
    /// Single-frame timings at these sizes.
    Frames {
        sizes: Vec<(u32, u32)>,
        repeats: usize,
        with_vulkan: bool,
    },
    /// The refocus batch.
    Batch {
        input: BatchInput,
        jobs: usize,
        files: FileFormats,
        /// Also the pipelined run on the Vulkan device.
        with_vulkan: bool,
    },
}

/// A checked benchmark.
#[derive(Debug, Clone)]
pub struct BenchJob {
    bench: Bench,
    gpu: GpuRequest,
}

/// What a benchmark measured.
#[derive(Debug)]
pub enum BenchReport {
    /// Single-frame timings: one table per capability, and every case.
    Frames {
        /// The renderer measured.
        renderer: String,
        /// Markdown tables.
        tables: Vec<String>,
        /// Every case measured.
        cases: Vec<BenchCase>,
        /// The Vulkan device measured (`--with-vulkan`).
        vulkan_device: Option<String>,
    },
    /// The batch benchmark.
    Batch(Box<BatchBench>),
}

impl BenchJob {
    /// Parses the sizes, or the batch input, thread count and compression.
    pub fn new(o: BenchOptions) -> Result<Self, ArgError> {
        let bench = match &o.batch {
            Some(batch) => {
                let input = match batch.parse::<usize>() {
                    Ok(0) => return Err(ArgError::NoBenchFrames),
                    Ok(n) if n > 100_000 => return Err(ArgError::TooManyBenchFrames(n)),
                    Ok(n) => BatchInput::Scene { frames: n },
                    Err(_) => BatchInput::Manifest(PathBuf::from(batch)),
                };
                let jobs = viewsynth::job::pool_threads(o.jobs)?;
                let files = FileFormats {
                    encoding: io::Encoding {
                        png: viewsynth::job::png_compression(&o.png_compression)?,
                        ..Default::default()
                    },
                    ..Default::default()
                };
                Bench::Batch {
                    input,
                    jobs,
                    files,
                    with_vulkan: o.with_vulkan,
                }
            }
            None => {
                let mut sizes = Vec::new();
                for s in &o.sizes {
                    let (w, h) = s.split_once('x').ok_or_else(|| ArgError::BenchSize(s.clone()))?;
                    let (w, h) = (w.parse::<u32>()?, h.parse::<u32>()?);
                    if w == 0 || h == 0 {
                        return Err(ArgError::BenchSize(s.clone()));
                    }
                    io::check_output_pixels("--sizes", w, h)?;
                    sizes.push((w, h));
                }
                Bench::Frames {
                    sizes,
                    repeats: o.repeats.max(1),
                    with_vulkan: o.with_vulkan,
                }
            }
        };
        Ok(BenchJob { bench, gpu: o.gpu })
    }

    /// `--device` names an EGL device; the Vulkan side takes the automatic choice.
    fn vulkan_request(&self) -> GpuRequest {
        GpuRequest {
            device: viewsynth::gpu::DeviceChoice::Auto,
            ..self.gpu
        }
    }

    /// Measures.
    pub fn run(&self, host: &dyn LabHost) -> Result<BenchReport, JobError> {
        let device = host.open_device(&self.gpu, viewsynth::job::Backend::Gl)?;
        match &self.bench {
            Bench::Batch {
                input,
                jobs,
                files,
                with_vulkan,
            } => {
                let vulkan = match with_vulkan {
                    true => Some(host.open_device(&self.vulkan_request(), viewsynth::job::Backend::Vulkan)?),
                    false => None,
                };
                Ok(BenchReport::Batch(Box::new(batch_bench(
                    &device,
                    input,
                    *jobs,
                    *files,
                    vulkan.as_ref(),
                )?)))
            }
            Bench::Frames {
                sizes,
                repeats,
                with_vulkan,
            } => {
                let mut cases = Vec::new();
                // Each capability's table is a stage of the progress shown (minutes on llvmpipe).
                let stages = HostStages(host);
                let total = 3 + usize::from(*with_vulkan);
                let measured = (|| -> Result<(Vec<String>, Option<String>), JobError> {
                    stages.stage(1, total, "bench: refocus");
                    let mut tables = vec![refocus_bench(&device, sizes, *repeats, &mut cases)?];
                    stages.stage(2, total, "bench: cyclopean");
                    tables.push(cyclopean_bench(&device, 1280, 720, *repeats, &mut cases)?);
                    stages.stage(3, total, "bench: stitch");
                    tables.push(crate::bench::stitch_bench(&device, *repeats, &mut cases)?);
                    if !*with_vulkan {
                        return Ok((tables, None));
                    }
                    stages.stage(4, total, "bench: every pass, GL against Vulkan");
                    let vk = host.open_device(&self.vulkan_request(), viewsynth::job::Backend::Vulkan)?;
                    let gl = device.clone();
                    let name = vk.renderer();
                    tables.push(crate::bench::passes::passes_bench(
                        &[("gl", gl), ("vulkan", vk)],
                        640,
                        480,
                        *repeats,
                        &mut cases,
                    )?);
                    Ok((tables, Some(name)))
                })();
                host.event(Event::Finished);
                let (tables, vulkan_device) = measured?;
                Ok(BenchReport::Frames {
                    renderer: device.renderer(),
                    tables,
                    cases,
                    vulkan_device,
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{ArgError, BatchInput, Bench, BenchJob, BenchOptions, GpuRequest};

    fn options(batch: Option<&str>, sizes: &[&str]) -> BenchOptions {
        BenchOptions {
            sizes: sizes.iter().map(|s| s.to_string()).collect(),
            repeats: 0,
            batch: batch.map(str::to_string),
            jobs: None,
            png_compression: "fast".into(),
            gpu: GpuRequest::default(),
            with_vulkan: false,
        }
    }

    #[test]
    fn sizes_and_batch_inputs_are_parsed_before_the_gpu_opens() {
        let job = BenchJob::new(options(None, &["640x480", "32x24"])).unwrap();
        assert!(matches!(&job.bench, Bench::Frames { sizes, repeats: 1, .. } if sizes == &[(640, 480), (32, 24)]));
        assert!(matches!(
            BenchJob::new(options(None, &["640"])),
            Err(ArgError::BenchSize(_))
        ));
        assert!(matches!(
            BenchJob::new(options(None, &["ax480"])),
            Err(ArgError::BenchSide(_))
        ));
        assert!(matches!(
            BenchJob::new(options(Some("0"), &[])),
            Err(ArgError::NoBenchFrames)
        ));
        let manifest = BenchJob::new(options(Some("frames.csv"), &["not a size"])).unwrap();
        assert!(matches!(
            manifest.bench,
            Bench::Batch {
                input: BatchInput::Manifest(_),
                ..
            }
        ));
    }
}
