/// The context opens (EGL, GL 4.5 core) and names its renderer.
mod context;
/// The pass/twin contract: each side's view is what its renderer or twin returns.
mod contract;
/// Every pass under the 8 conventions at 12 sizes gives the same view.
mod conventions_sweep;
/// Size limits come from the context; one past them is refused by name.
mod limits;
/// Every program compiles and links under every convention; every shader file is used.
mod shader_library;
