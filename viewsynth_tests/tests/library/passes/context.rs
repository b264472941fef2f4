use viewsynth_tests::gpu;

#[test]
fn context_is_gl_4_5_core_or_newer_with_sane_limits() {
    let g = gpu();
    let i = g.info();
    assert!((i.gl_major, i.gl_minor) >= (4, 5), "{i:?}");
    assert!(
        i.version.contains("Core") || i.version.starts_with('4'),
        "{}",
        i.version
    );
    assert!(i.max_texture_size >= 4096 && i.max_viewport[0] >= 4096, "{i:?}");
    assert!(["device", "surfaceless"].contains(&i.platform.as_str()));
}

#[test]
fn two_contexts_on_two_threads_work_independently() {
    let handles: Vec<_> = (0..2)
        .map(|_| std::thread::spawn(|| gpu().info().renderer.clone()))
        .collect();
    for h in handles {
        assert!(!h.join().expect("thread").is_empty());
    }
}
