"""Refocus a manifest of RGB-D frames into files with Ray Data: one viewsynth.Renderer (one GL
context) per actor, one actor per GPU.

    python python/examples/ray_refocus.py frames.csv out/ --scales 0.5,1,2
    python python/examples/ray_refocus.py frames.csv out/ --zoom-random 0.6,1.8 --samples 3 \
        --seed 7 --rgb-everywhere        # training-data augmentation, as the CLI's batch draws it

Ray is the scheduler: `ray.data.from_items` over the manifest's frames, `map_batches` with a
callable class whose actors each hold one Renderer (`num_gpus=1` per actor when the cluster has
GPUs, so Ray gives each its own GPU through CUDA_VISIBLE_DEVICES, which device="auto" follows; on
a CPU-only machine `num_gpus=0` and Mesa llvmpipe renders). Each actor writes its frames with
`Renderer.refocus_batch`, the library's batch: the same decoders, writers and folder layout as
`viewsynth refocus --batch MANIFEST --out-dir OUT`, so OUT/<frame name>/ holds the same files
either way (and a rerun skips finished frames, as the CLI's resume). Actors write no index
(`index=False`: each holds only a share); the driver writes OUT/index.jsonl once over the whole
manifest with viewsynth.write_index, so it equals the CLI's.

Every augmentation option of refocus_batch is an option here, as the CLI names it:
--zoom-random LO,HI with --samples K and --seed S (each frame's scales drawn from the seed and
its name, so any split over actors draws what the CLI draws), --rgb-everywhere, --size W,H and
--depth-trunc; --verify checks finished frames' files as the CLI's --verify.

On a real cluster the manifest's input files and OUT must be on a shared file system (NFS,
Lustre, a mounted bucket) at the same path on every node: each actor reads the paths the
manifest names and writes OUT/<frame name>/ on whatever node it runs, and the driver reads every
frame's manifest.json to write the index. Relative paths resolve against the manifest's folder
(and OUT against each process's working folder), so give absolute ones there.

The manifest is the CLI's (CSV with rgb,depth,fx,fy,cx,cy[,depth_scale,name], or JSON); frame
names come from viewsynth.load_manifest, so they do not depend on how Ray splits the frames.
Exit status 1 when a frame failed (each failure is printed).
"""

import argparse
import sys
import threading

import ray
import ray.data

import viewsynth as vs


class RefocusFrames:
    """A Ray Data actor: a share of the frames per call, one Renderer for the actor's life."""

    def __init__(self, out_dir, options):
        self.out_dir = out_dir
        # Each call holds an arbitrary share of the manifest: the driver writes the index.
        self.options = dict(options, index=False)
        # A Renderer belongs to the thread that opened it; Ray may call from another thread
        # than the constructor's, so open it lazily on the calling thread.
        self.local = threading.local()

    def renderer(self):
        if getattr(self.local, "renderer", None) is None:
            self.local.renderer = vs.Renderer()
        return self.local.renderer

    def __call__(self, batch):
        # Column arrays (numpy) to one plain dict per frame, Python scalars and strings.
        columns = {k: v.tolist() for k, v in batch.items()}
        frames = [dict(zip(columns, values)) for values in zip(*columns.values())]
        summary = self.renderer().refocus_batch(frames, self.out_dir, **self.options)
        failed = dict((name, error) for name, error in summary["failed"])
        return {
            "name": [f["name"] for f in frames],
            "ok": [f["name"] not in failed for f in frames],
            "error": [failed.get(f["name"], "") for f in frames],
        }


def refocus_with_ray(manifest, out_dir, options, batch_size=4, max_actors=None):
    """Refocus every frame of `manifest` into `out_dir` on the running Ray cluster (ray.init
    first), then write out_dir/index.jsonl over the whole manifest; returns a list of
    {"name", "ok", "error"}, one per frame."""
    frames = vs.load_manifest(manifest)
    gpus = int(ray.cluster_resources().get("GPU", 0))
    if max_actors is None:
        max_actors = gpus if gpus else 2
    ds = ray.data.from_items(frames)
    results = ds.map_batches(
        RefocusFrames,
        fn_constructor_kwargs={"out_dir": str(out_dir), "options": options},
        batch_size=batch_size,
        batch_format="numpy",
        num_gpus=1 if gpus else 0,
        compute=ray.data.ActorPoolStrategy(min_size=1, max_size=max_actors),
    )
    results = sorted(results.take_all(), key=lambda r: r["name"])
    settings = {k: v for k, v in options.items() if k not in ("resume", "verify", "jobs")}
    vs.write_index(frames, out_dir, **settings)
    return results


def numbers(text, kind=float):
    return [kind(v) for v in text.split(",")]


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("manifest")
    p.add_argument("out_dir")
    p.add_argument("--scales", default=None, help="focal scales, as the CLI's --zoom-range (default 0.5,0.75,1,1.5,2)")
    p.add_argument("--zoom-random", default=None, metavar="LO,HI",
                   help="draw --samples scales per frame, log-uniform in [LO, HI], instead of --scales")
    p.add_argument("--samples", type=int, default=None, help="scales drawn per frame with --zoom-random")
    p.add_argument("--seed", type=int, default=None, help="seed of the --zoom-random draws")
    p.add_argument("--rgb-everywhere", action="store_true",
                   help="colour every pixel inside the source frame (mask and depth unchanged)")
    p.add_argument("--size", default=None, metavar="W,H", help="output size in pixels (default: each source's)")
    p.add_argument("--depth-trunc", type=float, default=None, help="input depth beyond this many metres is invalid")
    p.add_argument("--depth-format", default="exr", help="any of exr,npy,png16, as the CLI's")
    p.add_argument("--outputs", default="rgb,depth,mask")
    p.add_argument("--force", action="store_true", help="render finished frames again (the CLI's --force)")
    p.add_argument("--verify", action="store_true",
                   help="also check finished frames' file CRCs and inputs' content (the CLI's --verify)")
    p.add_argument("--jobs", type=int, default=1, help="decode/encode threads per actor")
    p.add_argument("--batch-size", type=int, default=4, help="frames per map_batches call")
    p.add_argument("--max-actors", type=int, default=None, help="default: the GPU count, else 2")
    p.add_argument("--address", default=None, help="Ray cluster address (default: start a local one)")
    p.add_argument("--num-cpus", type=int, default=None, help="CPUs of the local Ray instance")
    return p.parse_args(argv)


def batch_options(a):
    """refocus_batch's keyword arguments from the parsed options (what is not given is left to
    refocus_batch's defaults, which check the combination as the CLI does)."""
    options = {
        "depth_format": a.depth_format,
        "outputs": a.outputs.split(","),
        "resume": not a.force,
        "verify": a.verify,
        "jobs": a.jobs,
        "rgb_everywhere": a.rgb_everywhere,
    }
    given = {
        "scales": a.scales and numbers(a.scales),
        "zoom_random": a.zoom_random and tuple(numbers(a.zoom_random)),
        "samples": a.samples,
        "seed": a.seed,
        "size": a.size and tuple(numbers(a.size, int)),
        "depth_trunc": a.depth_trunc,
    }
    options.update({k: v for k, v in given.items() if v is not None})
    return options


def main(argv=None):
    a = parse_args(argv)
    options = batch_options(a)
    ray.init(address=a.address, num_cpus=a.num_cpus, include_dashboard=False)
    try:
        results = refocus_with_ray(a.manifest, a.out_dir, options, a.batch_size, a.max_actors)
    finally:
        ray.shutdown()
    failed = [r for r in results if not r["ok"]]
    for r in failed:
        print(f"failed: {r['name']}: {r['error']}", file=sys.stderr)
    print(f"{len(results)} frames: {len(results) - len(failed)} done, {len(failed)} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
