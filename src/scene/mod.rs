//! scene: ground-truth frames of the built-in scenes ([`crate::world`]: the shapes and their
//! f64 ray tracer), ray traced on the GPU for any GL camera ([`render`], its f64 twin [`reference`]), with cameras and cube
//! faces (the `scene` command).

pub mod reference;
pub mod render;
