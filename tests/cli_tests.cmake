# CLI-level tests of bad scene input (included by tests/CMakeLists.txt): `canopy render <file>`
# must exit with code 2 and print the one-line SceneError message on stderr. Every
# tests/data/bad/*.json carries its expected message in its first line ("// expect: ...").
file(GLOB CANOPY_BAD_SCENES CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/data/bad/*.json)
foreach(scene ${CANOPY_BAD_SCENES})
  get_filename_component(stem ${scene} NAME_WE)
  add_test(NAME cli_bad_${stem}
    COMMAND ${CMAKE_COMMAND} -DEXE=$<TARGET_FILE:canopy> -DSCENE=${scene}
            -P ${CMAKE_CURRENT_SOURCE_DIR}/check_exit2.cmake)
  set_tests_properties(cli_bad_${stem} PROPERTIES LABELS cli TIMEOUT 120)
endforeach()

# A scene file that does not exist.
set(missing ${CMAKE_CURRENT_SOURCE_DIR}/data/bad/no_such_scene.json)
add_test(NAME cli_missing_scene_file
  COMMAND ${CMAKE_COMMAND} -DEXE=$<TARGET_FILE:canopy> -DSCENE=${missing}
          "-DEXPECT=${missing}: cannot open file"
          -P ${CMAKE_CURRENT_SOURCE_DIR}/check_exit2.cmake)
set_tests_properties(cli_missing_scene_file PROPERTIES LABELS cli TIMEOUT 120)

# The orientation ablation applies to the tree samplers only.
add_test(NAME cli_no_orientation_needs_a_tree
  COMMAND ${CMAKE_COMMAND} -DEXE=$<TARGET_FILE:canopy>
          -DSCENE=${CMAKE_CURRENT_SOURCE_DIR}/../scenes/default.json
          "-DARGS=--light-sampler;power;--no-orientation"
          "-DEXPECT=--no-orientation: applies to the tree samplers only (tree, tree-split), not power"
          -P ${CMAKE_CURRENT_SOURCE_DIR}/check_exit2.cmake)
set_tests_properties(cli_no_orientation_needs_a_tree PROPERTIES LABELS cli TIMEOUT 120)

# ---------------------------------------------------------------- issue 9: input that cannot crash
# or hang, outputs written atomically, reasonable input accepted (docs/limits.md).
set(CANOPY_CHECK2 ${CMAKE_CURRENT_SOURCE_DIR}/check_exit2.cmake)
set(CANOPY_CHECK_CLI ${CMAKE_CURRENT_SOURCE_DIR}/check_cli.cmake)
set(CANOPY_LIMITS_DATA ${CMAKE_CURRENT_SOURCE_DIR}/data/limits)
set(CANOPY_SCRATCH ${CMAKE_CURRENT_BINARY_DIR}/cli_scratch)
file(MAKE_DIRECTORY ${CANOPY_SCRATCH})
# ARGS, FILES, MAGIC and ENV lists are written with "|" (a ";" would split them here).
function(canopy_cli_test name)
  add_test(NAME ${name} COMMAND ${CMAKE_COMMAND} -DEXE=$<TARGET_FILE:canopy> ${ARGN})
  set_tests_properties(${name} PROPERTIES LABELS cli TIMEOUT 120)
endfunction()

# A FIFO as the scene path: refused at once (it used to block forever in open()).
canopy_cli_test(cli_scene_fifo -DSCENE=${CANOPY_SCRATCH}/fifo_scene.json -DMKFIFO=ON -DTIMEOUT=10
  "-DEXPECT=${CANOPY_SCRATCH}/fifo_scene.json: cannot open file (it is a FIFO, not a regular file)"
  -P ${CANOPY_CHECK2})
# A character device: refused (it used to be read without bound).
canopy_cli_test(cli_scene_dev_zero -DSCENE=/dev/zero -DTIMEOUT=10
  "-DEXPECT=/dev/zero: cannot open file (it is a character device, not a regular file)"
  -P ${CANOPY_CHECK2})
# A scene file over the size limit (a sparse file: no disk space used).
canopy_cli_test(cli_scene_too_large -DSCENE=${CANOPY_SCRATCH}/large_scene.json -DSPARSE=268435457
  -DTIMEOUT=10
  "-DEXPECT=${CANOPY_SCRATCH}/large_scene.json: file is too large (268435457 bytes, the limit is 256 MiB)"
  -P ${CANOPY_CHECK2})
# NaN and infinity on the command line.
canopy_cli_test(cli_split_threshold_nan -DSCENE=${CANOPY_LIMITS_DATA}/tiny.json
  "-DARGS=--split-threshold|nan"
  "-DEXPECT=canopy: --split-threshold: must be a finite number (see --help)" -P ${CANOPY_CHECK2})
canopy_cli_test(cli_split_threshold_inf -DSCENE=${CANOPY_LIMITS_DATA}/tiny.json
  "-DARGS=--split-threshold|inf"
  "-DEXPECT=canopy: --split-threshold: must be a finite number (see --help)" -P ${CANOPY_CHECK2})
# A CLI11 parse error is one line.
canopy_cli_test(cli_parse_error_one_line -DSCENE=${CANOPY_LIMITS_DATA}/tiny.json
  "-DARGS=--spp|many" "-DEXPECT=canopy: Could not convert: --spp = many (see --help)"
  -P ${CANOPY_CHECK2})
# A film too large for the device: one line naming the buffer, its bytes and the limit, exit 2,
# before any rendering (it used to die with std::bad_alloc after a minute).
canopy_cli_test(cli_film_exceeds_device -DSCENE=${CANOPY_LIMITS_DATA}/huge_film.json
  -DENV=POCL_MEMORY_LIMIT=1 -DPREFIX=ON -DTIMEOUT=30
  "-DEXPECT=${CANOPY_LIMITS_DATA}/huge_film.json: device buffer film_sum needs 8589934592 bytes (8.00 GiB), more than the device's largest allocation (CL_DEVICE_MAX_MEM_ALLOC_SIZE "
  -P ${CANOPY_CHECK2})
# Too many lights for the device (it used to fail with a bare "canopy: clCreateBuffer").
canopy_cli_test(cli_lights_exceed_device -DSCENE=${CANOPY_LIMITS_DATA}/many_lights.json
  -DENV=POCL_MEMORY_LIMIT=1 -DPREFIX=ON -DTIMEOUT=30
  "-DEXPECT=${CANOPY_LIMITS_DATA}/many_lights.json: device buffer lights needs 288000000 bytes (274.7 MiB), more than the device's largest allocation (CL_DEVICE_MAX_MEM_ALLOC_SIZE "
  -P ${CANOPY_CHECK2})

# Outputs: replaced only by rename (the previous file is never written into).
canopy_cli_test(cli_output_atomic -DSCENE=${CANOPY_LIMITS_DATA}/tiny.json
  -DDIR=${CANOPY_SCRATCH}/atomic -P ${CMAKE_CURRENT_SOURCE_DIR}/check_output_atomic.cmake)
# An unwritable --out is refused before rendering.
file(WRITE ${CANOPY_SCRATCH}/not_a_dir "")
canopy_cli_test(cli_out_unwritable -DSCENE=${CANOPY_LIMITS_DATA}/tiny.json
  "-DARGS=--out|${CANOPY_SCRATCH}/not_a_dir/x.exr" -DTIMEOUT=10
  "-DEXPECT=--out: ${CANOPY_SCRATCH}/not_a_dir/x.exr: its directory ${CANOPY_SCRATCH}/not_a_dir is not a directory"
  -P ${CANOPY_CHECK2})
# --out x.png: the PNG there and the EXR beside it, each in its own format.
canopy_cli_test(cli_out_png
  "-DARGS=render|${CANOPY_LIMITS_DATA}/tiny.json|--out|${CANOPY_SCRATCH}/outpng/x.png"
  "-DFILES=${CANOPY_SCRATCH}/outpng/x.png|${CANOPY_SCRATCH}/outpng/x.exr"
  "-DMAGIC=89504e47|762f3101" -P ${CANOPY_CHECK_CLI})
# --png with another extension is refused (it would write a PNG under that name).
canopy_cli_test(cli_png_wrong_extension -DSCENE=${CANOPY_LIMITS_DATA}/tiny.json
  "-DARGS=--out|${CANOPY_SCRATCH}/a.exr|--png|${CANOPY_SCRATCH}/a.exr"
  "-DEXPECT=--png: ${CANOPY_SCRATCH}/a.exr: must end in .png" -P ${CANOPY_CHECK2})

# Reasonable input accepted: lights switched off are skipped and counted; count 0 light sets.
canopy_cli_test(cli_lights_switched_off
  "-DARGS=render|${CANOPY_LIMITS_DATA}/off_lights.json|--out|${CANOPY_SCRATCH}/off.exr"
  "-DSTDERR=1 lights (4 with zero emission skipped)" "-DFILES=${CANOPY_SCRATCH}/off.exr"
  -P ${CANOPY_CHECK_CLI})
# No emitters: a black image, a one-line warning, exit 0.
canopy_cli_test(cli_no_emitters
  "-DARGS=render|${CANOPY_LIMITS_DATA}/no_emitters.json|--out|${CANOPY_SCRATCH}/black.exr"
  "-DSTDERR=canopy: warning: ${CANOPY_LIMITS_DATA}/no_emitters.json: the scene has no emitters; the image is black"
  "-DFILES=${CANOPY_SCRATCH}/black.exr" -P ${CANOPY_CHECK_CLI})
# --spp above 10^6 (the scene format allows 2^24).
canopy_cli_test(cli_spp_above_a_million
  "-DARGS=render|${CANOPY_LIMITS_DATA}/tiny.json|--spp|1048576|--out|${CANOPY_SCRATCH}/spp.exr"
  "-DSTDERR=2x2, 1048576 spp" -DTIMEOUT=60 -P ${CANOPY_CHECK_CLI})
canopy_cli_test(cli_spp_above_format_limit -DSCENE=${CANOPY_LIMITS_DATA}/tiny.json
  "-DARGS=--spp|16777217" "-DEXPECT=--spp: must be in [1, 16777216], got 16777217"
  -P ${CANOPY_CHECK2})
# Issues 10 and 20: a scene without sampler settings renders with the measured default (auto: a
# pilot picks the sampler, and says which) and pbrt-v4's default depth, and the summary line says
# so; a partial render takes brdf-mis without a pilot (its parts must merge exactly); --max-cut
# and --max-depth override the scene and are range-checked.
canopy_cli_test(cli_default_sampler_auto
  "-DARGS=render|${CANOPY_LIMITS_DATA}/tiny.json|--out|${CANOPY_SCRATCH}/defaults.exr"
  "-DSTDERR=canopy: auto: " -P ${CANOPY_CHECK_CLI})
canopy_cli_test(cli_default_sampler_summary
  "-DARGS=render|${CANOPY_LIMITS_DATA}/tiny.json|--out|${CANOPY_SCRATCH}/defaults2.exr"
  "-DSTDERR=max depth 5, 1 lights" -P ${CANOPY_CHECK_CLI})
canopy_cli_test(cli_default_sampler_partial
  "-DARGS=render|${CANOPY_LIMITS_DATA}/tiny.json|--samples|0:1|--out|${CANOPY_SCRATCH}/defaults3.exr"
  "-DSTDERR=1 spp (samples 0:1), sampler brdf-mis (threshold 0.25, max cut 64, delta 0.5, N_max 50, lambda 10), max depth 5, 1 lights"
  -P ${CANOPY_CHECK_CLI})
canopy_cli_test(cli_max_cut_option
  "-DARGS=render|${CANOPY_LIMITS_DATA}/tiny.json|--light-sampler|tree-split|--max-cut|3|--max-depth|2|--out|${CANOPY_SCRATCH}/max_cut.exr"
  "-DSTDERR=sampler tree-split (threshold 0.25, max cut 3), max depth 2" -P ${CANOPY_CHECK_CLI})
canopy_cli_test(cli_max_cut_zero -DSCENE=${CANOPY_LIMITS_DATA}/tiny.json
  "-DARGS=--max-cut|0" "-DEXPECT=--max-cut: must be in [1, 65536], got 0" -P ${CANOPY_CHECK2})
canopy_cli_test(cli_max_depth_too_large -DSCENE=${CANOPY_LIMITS_DATA}/tiny.json
  "-DARGS=--max-depth|1025" "-DEXPECT=--max-depth: must be in [1, 1024], got 1025"
  -P ${CANOPY_CHECK2})
# Issue 11: MIS off. `canopy render --no-mis` says so on the summary line; `canopy converge
# --samplers` takes a trailing /nomis (tests/cli_tools.cmake checks that it renders with MIS off),
# refuses any other suffix and refuses /nomis on bsdf (BSDF sampling only), before rendering.
canopy_cli_test(cli_render_no_mis
  "-DARGS=render|${CANOPY_LIMITS_DATA}/tiny.json|--light-sampler|tree-split|--no-mis|--out|${CANOPY_SCRATCH}/no_mis.exr"
  "-DSTDERR=sampler tree-split (threshold 0.25, max cut 64, no MIS)" -P ${CANOPY_CHECK_CLI})
# The path sampler is sobol or independent (render --sampler, converge --sampler or a suffix).
canopy_cli_test(cli_render_bad_path_sampler
  "-DARGS=render|${CANOPY_LIMITS_DATA}/tiny.json|--sampler|halton|--out|${CANOPY_SCRATCH}/halton.exr"
  -DRC=2 "-DSTDERR=--sampler: 'halton': must be independent or sobol"
  -DONE_LINE=ON -P ${CANOPY_CHECK_CLI})
canopy_cli_test(cli_converge_bad_mis_suffix
  "-DARGS=converge|${CANOPY_LIMITS_DATA}/tiny.json|--reference|${CANOPY_SCRATCH}/none.exr|--samplers|power,tree-split:0.5/mis"
  -DRC=2 "-DSTDERR=--samplers: 'tree-split:0.5/mis': unknown or repeated suffix '/mis' (/nomis: MIS off; /equal: brdf-mis with equal allocation)"
  -DONE_LINE=ON -P ${CANOPY_CHECK_CLI})
# Issue 20: "/split=T" sets the split threshold where ":T" is brdf-mis' delta; out of range is
# refused before rendering.
canopy_cli_test(cli_converge_bad_split_suffix
  "-DARGS=converge|${CANOPY_LIMITS_DATA}/tiny.json|--reference|${CANOPY_SCRATCH}/none.exr|--samplers|brdf-mis/split=2"
  -DRC=2 "-DSTDERR=--samplers: 'brdf-mis/split=2': /split=T: T must be a number in [0, 1]"
  -DONE_LINE=ON -P ${CANOPY_CHECK_CLI})
# Issue 21: "/nmax=N" sets the BRDF samplers' N_max (render --brdf-nmax's range), refused before
# rendering when out of range.
canopy_cli_test(cli_converge_bad_nmax_suffix
  "-DARGS=converge|${CANOPY_LIMITS_DATA}/tiny.json|--reference|${CANOPY_SCRATCH}/none.exr|--samplers|brdf-mis/nmax=0"
  -DRC=2 "-DSTDERR=--samplers: 'brdf-mis/nmax=0': /nmax=N: N must be an integer in [1, 1024]"
  -DONE_LINE=ON -P ${CANOPY_CHECK_CLI})
# "/maxcut=N" sets tree-split's cut cap (render --max-cut's range), refused before any render.
canopy_cli_test(cli_converge_bad_maxcut_suffix
  "-DARGS=converge|${CANOPY_LIMITS_DATA}/tiny.json|--reference|${CANOPY_SCRATCH}/none.exr|--samplers|tree-split/maxcut=x"
  -DRC=2 "-DSTDERR=--samplers: 'tree-split/maxcut=x': /maxcut=N: N must be an integer in [1, 65536]"
  -DONE_LINE=ON -P ${CANOPY_CHECK_CLI})
canopy_cli_test(cli_converge_bsdf_nomis
  "-DARGS=converge|${CANOPY_LIMITS_DATA}/tiny.json|--reference|${CANOPY_SCRATCH}/none.exr|--samplers|bsdf/nomis"
  -DRC=2 "-DSTDERR=--samplers: 'bsdf/nomis': /nomis does not apply to bsdf (BSDF sampling only: there is no light sample to combine with)"
  -DONE_LINE=ON -P ${CANOPY_CHECK_CLI})
# Issue 12: brdf-mis/equal is brdf-mis with equal allocation; /equal means nothing to other
# samplers, and brdf-mis:D takes delta in [0, 1000] (as render --brdf-delta), refused before rendering.
canopy_cli_test(cli_converge_equal_not_brdf_mis
  "-DARGS=converge|${CANOPY_LIMITS_DATA}/tiny.json|--reference|${CANOPY_SCRATCH}/none.exr|--samplers|brdf-mis/equal,power/equal"
  -DRC=2 "-DSTDERR=--samplers: 'power/equal': /equal applies to brdf-mis only (equal allocation between its BRDF-oriented and BSDF samples)"
  -DONE_LINE=ON -P ${CANOPY_CHECK_CLI})
canopy_cli_test(cli_converge_brdf_delta_range
  "-DARGS=converge|${CANOPY_LIMITS_DATA}/tiny.json|--reference|${CANOPY_SCRATCH}/none.exr|--samplers|brdf-mis:0.05,brdf-oriented:1001"
  -DRC=2 "-DSTDERR=--samplers: 'brdf-oriented:1001': the BRDF split threshold delta must be a number in [0, 1000]"
  -DONE_LINE=ON -P ${CANOPY_CHECK_CLI})
# NaN is refused by every floating-point option, of every subcommand.
canopy_cli_test(cli_converge_budget_nan
  "-DARGS=converge|${CANOPY_LIMITS_DATA}/tiny.json|--reference|${CANOPY_SCRATCH}/none.exr|--budget|nan"
  -DRC=2 "-DSTDERR=canopy: --budget: must be a finite number (see --help)" -DONE_LINE=ON
  -P ${CANOPY_CHECK_CLI})
canopy_cli_test(cli_compare_error_scale_nan
  "-DARGS=compare|${CANOPY_SCRATCH}/a.exr|${CANOPY_SCRATCH}/b.exr|--error-scale|nan"
  -DRC=2 "-DSTDERR=canopy: --error-scale: must be a finite number (see --help)" -DONE_LINE=ON
  -P ${CANOPY_CHECK_CLI})

# A film whose pixels exceed FLT_MAX: exit 0, one warning line, counted in the stats, finite image.
add_test(NAME cli_film_overflow_is_counted_and_finite
  COMMAND ${CMAKE_COMMAND} -DEXE=$<TARGET_FILE:canopy>
          -DSCENE=${CMAKE_CURRENT_SOURCE_DIR}/data/film_overflow.json
          -DWORK=${CMAKE_CURRENT_BINARY_DIR}/film_overflow
          -P ${CMAKE_CURRENT_SOURCE_DIR}/check_film_overflow.cmake)
set_tests_properties(cli_film_overflow_is_counted_and_finite PROPERTIES LABELS cli TIMEOUT 180)

# ---------------------------------------------------------------- pbrt-v4 scenes (the first slice)
set(CANOPY_PBRT_DATA ${CMAKE_CURRENT_SOURCE_DIR}/data/pbrt)
# A small .pbrt scene renders (the extension selects the pbrt reader).
canopy_cli_test(cli_pbrt_render_small
  "-DARGS=render|${CANOPY_PBRT_DATA}/small.pbrt|--spp|1|--quiet|--out|${CANOPY_SCRATCH}/pbrt_small.exr"
  "-DNOT_STDERR=warning" "-DFILES=${CANOPY_SCRATCH}/pbrt_small.exr" -P ${CANOPY_CHECK_CLI})
# A construct the reader skips: a one-line warning naming file:line, and the render goes on.
canopy_cli_test(cli_pbrt_warning
  "-DARGS=render|${CANOPY_PBRT_DATA}/warn.pbrt|--spp|1|--quiet|--out|${CANOPY_SCRATCH}/pbrt_warn.exr"
  "-DSTDERR=canopy: warning: ${CANOPY_PBRT_DATA}/warn.pbrt:6: LightSource \"goniometric\" is not read in this slice, ignored"
  -P ${CANOPY_CHECK_CLI})
# --strict: the same warning is an error, exit 2, one line.
canopy_cli_test(cli_pbrt_strict -DSCENE=${CANOPY_PBRT_DATA}/warn.pbrt "-DARGS=--strict"
  "-DEXPECT=${CANOPY_PBRT_DATA}/warn.pbrt:6: LightSource \"goniometric\" is not read in this slice, ignored (--strict: warnings are errors)"
  -P ${CANOPY_CHECK2})
# The Film's filename is the default output (relative to the working directory, as pbrt writes it).
canopy_cli_test(cli_pbrt_film_output
  "-DARGS=render|${CANOPY_PBRT_DATA}/film_output.pbrt|--quiet"
  "-DFILES=${CMAKE_CURRENT_BINARY_DIR}/pbrt_film_out.png|${CMAKE_CURRENT_BINARY_DIR}/pbrt_film_out.exr"
  -P ${CANOPY_CHECK_CLI})
# A plymesh scene renders; a truncated PLY file is exit 2 with one line naming it and the
# directive.
canopy_cli_test(cli_pbrt_render_plymesh
  "-DARGS=render|${CANOPY_PBRT_DATA}/ply_scene.pbrt|--spp|1|--quiet|--out|${CANOPY_SCRATCH}/pbrt_ply.exr"
  "-DNOT_STDERR=warning" "-DFILES=${CANOPY_SCRATCH}/pbrt_ply.exr" -P ${CANOPY_CHECK_CLI})
canopy_cli_test(cli_pbrt_plymesh_truncated -DSCENE=${CANOPY_PBRT_DATA}/ply_truncated.pbrt
  "-DEXPECT=${CANOPY_PBRT_DATA}/ply_truncated.pbrt:5: Shape \"plymesh\" \"${CANOPY_PBRT_DATA}/truncated.ply\": truncated: the file ends in vertex 2 of 3 (189 bytes)"
  -P ${CANOPY_CHECK2})
# A textured scene renders (image textures for reflectance and roughness, read at render time);
# a texture whose file is missing is exit 2 with one line naming file:line.
canopy_cli_test(cli_pbrt_render_textured
  "-DARGS=render|${CANOPY_PBRT_DATA}/textured.pbrt|--spp|1|--quiet|--out|${CANOPY_SCRATCH}/pbrt_textured.exr"
  "-DNOT_STDERR=warning" "-DFILES=${CANOPY_SCRATCH}/pbrt_textured.exr" -P ${CANOPY_CHECK_CLI})
canopy_cli_test(cli_pbrt_texture_missing -DSCENE=${CANOPY_PBRT_DATA}/texture_missing.pbrt
  "-DEXPECT=${CANOPY_PBRT_DATA}/texture_missing.pbrt:4: Texture \"wood\": \"string filename\" ${CANOPY_PBRT_DATA}/textures/no_such.png: no such file"
  -P ${CANOPY_CHECK2})
# A corrupt image is one line too: libpng's own "libpng error: ..." line (printed on stderr by the
# library itself) must not precede Canopy's message (PREFIX: the message alone on stderr). A PNG
# texture cut in half names the Texture's file:line and the image; an environment map whose IHDR
# is invalid names the LightSource's file:line and the image.
canopy_cli_test(cli_pbrt_texture_truncated_png -DSCENE=${CANOPY_PBRT_DATA}/texture_truncated.pbrt
  -DPREFIX=ON
  "-DEXPECT=${CANOPY_PBRT_DATA}/texture_truncated.pbrt:6: texture \"wood\": ${CANOPY_PBRT_DATA}/textures/truncated.png: cannot read the texture"
  -P ${CANOPY_CHECK2})
canopy_cli_test(cli_pbrt_envmap_bad_ihdr_png -DSCENE=${CANOPY_PBRT_DATA}/envmap_bad_ihdr.pbrt
  -DPREFIX=ON
  "-DEXPECT=${CANOPY_PBRT_DATA}/envmap_bad_ihdr.pbrt:6: LightSource \"infinite\": ${CANOPY_PBRT_DATA}/textures/bad_ihdr.png: cannot read the environment map"
  -P ${CANOPY_CHECK2})
# An Include cycle: exit 2, the cycle named.
canopy_cli_test(cli_pbrt_include_cycle -DSCENE=${CANOPY_PBRT_DATA}/cycle_a.pbrt
  "-DEXPECT=${CANOPY_PBRT_DATA}/cycle_b.pbrt:2: Include cycle: ${CANOPY_PBRT_DATA}/cycle_a.pbrt -> ${CANOPY_PBRT_DATA}/cycle_b.pbrt -> ${CANOPY_PBRT_DATA}/cycle_a.pbrt"
  -P ${CANOPY_CHECK2})
