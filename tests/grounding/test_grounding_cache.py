"""The persistent compilation cache points JAX at the folder asked for and caches small programs too."""

import jax

import grounding


def test_enable_cache_sets_the_folder_and_thresholds(tmp_path, monkeypatch):
    before = jax.config.jax_compilation_cache_dir
    try:
        path = grounding.enable_cache(tmp_path / "c")
        assert path.is_dir()
        assert jax.config.jax_compilation_cache_dir == str(path)
        assert jax.config.jax_persistent_cache_min_compile_time_secs == 0.0
        monkeypatch.setenv("LV3D_CACHE", str(tmp_path / "root"))
        assert grounding.enable_cache() == (tmp_path / "root" / "jax").resolve()
    finally:
        if before:
            grounding.enable_cache(before)
