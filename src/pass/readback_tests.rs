//! A run's missing output, raised by backend-neutral code, names the API the run was on: the GL
//! message as it always was, and no "OpenGL error" on a Vulkan run.

use super::{Api, Rendered, Texels, Timing};

/// A run's outputs on `api`, location 0 read back and location 1 not asked for.
fn rendered(api: Api) -> Rendered {
    Rendered {
        outputs: vec![Some(Texels::Bytes(vec![7; 4])), None],
        timing: Timing {
            gpu_ms: None,
            wall_ms: 0.0,
        },
        size: (2, 2),
        api,
    }
}

#[test]
fn a_missing_output_of_a_vulkan_run_is_a_vulkan_error() {
    let mut r = rendered(Api::Vulkan);
    assert_eq!(r.take(0, "densify flags").unwrap(), vec![7; 4]);
    let e = r.take(1, "densify flags").unwrap_err().to_string();
    assert_eq!(e, "Vulkan error: densify flags: output 1 was not rendered");
    assert!(!e.contains("OpenGL"), "{e}");
    let e = r.take_floats(5, "stereo matcher").unwrap_err().to_string();
    assert!(e.starts_with("Vulkan error: ") && !e.contains("OpenGL"), "{e}");
}

#[test]
fn a_missing_output_of_a_gl_run_keeps_its_opengl_message() {
    let mut r = rendered(Api::Gl);
    let e = r.take(1, "densify flags").unwrap_err().to_string();
    assert_eq!(e, "OpenGL error: densify flags: output 1 was not rendered");
    assert_eq!(
        Api::Gl
            .readback_error("densify: the disparity was not read back")
            .to_string(),
        crate::Error::Gl("densify: the disparity was not read back".into()).to_string()
    );
}
