# CLI tests of `canopy compare` and `canopy converge` (label cli). Included by tests/CMakeLists.txt
# to register the tests; the same file, run with `cmake -DMODE=... -P cli_tools.cmake`, is the
# test driver (so the registration and the checks stay together).
#   MODE=compare   EXE, OIIOTOOL, DIR: two tiny EXRs made with oiiotool; output, exit codes
#   MODE=converge  EXE, SCENE, DIR: a 2-second converge run writes the CSVs and both plots; an
#                  equal-time run (--equal-time, --max-depth 1) writes the statistics columns
#   MODE=merge     EXE, SCENE, OTHER, LONG, DIR: `render --samples/--crop` and `merge` (issue 23):
#                  ranges merge into one range, every inconsistent input is refused with one line;
#                  progress in a log is whole lines (LONG: a scene that renders for > 1 s)

if(NOT CMAKE_SCRIPT_MODE_FILE)
  # ------------------------------------------------------------------ registration
  find_program(CANOPY_OIIOTOOL oiiotool)
  if(CANOPY_OIIOTOOL)
    add_test(NAME cli_compare
      COMMAND ${CMAKE_COMMAND} -DMODE=compare -DEXE=$<TARGET_FILE:canopy>
              -DOIIOTOOL=${CANOPY_OIIOTOOL} -DDIR=${CMAKE_CURRENT_BINARY_DIR}/cli_compare
              -P ${CMAKE_CURRENT_LIST_FILE})
    set_tests_properties(cli_compare PROPERTIES LABELS cli TIMEOUT 120)
  endif()
  add_test(NAME cli_converge
    COMMAND ${CMAKE_COMMAND} -DMODE=converge -DEXE=$<TARGET_FILE:canopy>
            -DSCENE=${CMAKE_CURRENT_SOURCE_DIR}/data/tiny_converge.json
            -DDIR=${CMAKE_CURRENT_BINARY_DIR}/cli_converge -P ${CMAKE_CURRENT_LIST_FILE})
  set_tests_properties(cli_converge PROPERTIES LABELS cli TIMEOUT 600
                       ENVIRONMENT CANOPY_KERNEL_WERROR=1)
  add_test(NAME cli_merge
    COMMAND ${CMAKE_COMMAND} -DMODE=merge -DEXE=$<TARGET_FILE:canopy>
            -DSCENE=${CMAKE_CURRENT_SOURCE_DIR}/data/tiny_converge.json
            -DOTHER=${CMAKE_CURRENT_SOURCE_DIR}/data/limits/tiny.json
            -DLONG=${CMAKE_SOURCE_DIR}/scenes/default.json
            -DDIR=${CMAKE_CURRENT_BINARY_DIR}/cli_merge -P ${CMAKE_CURRENT_LIST_FILE})
  set_tests_properties(cli_merge PROPERTIES LABELS cli TIMEOUT 600
                       ENVIRONMENT CANOPY_KERNEL_WERROR=1)
  return()
endif()

# -------------------------------------------------------------------- driver
function(run_canopy expected_rc)
  execute_process(COMMAND "${EXE}" ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out
                  ERROR_VARIABLE err TIMEOUT 500)
  if(NOT rc STREQUAL "${expected_rc}")
    message(FATAL_ERROR "canopy ${ARGN}: expected exit code ${expected_rc}, got '${rc}'\n"
                        "stdout:\n${out}\nstderr:\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
  set(err "${err}" PARENT_SCOPE)
endfunction()

function(expect_contains text what)
  string(FIND "${text}" "${what}" pos)
  if(pos EQUAL -1)
    message(FATAL_ERROR "expected to find '${what}' in:\n${text}")
  endif()
endfunction()

file(REMOVE_RECURSE "${DIR}")
file(MAKE_DIRECTORY "${DIR}")

if(MODE STREQUAL "compare")
  # A = 0.5 everywhere, B = 0.25 everywhere: RMSE 0.25, relMSE 0.0625 / (0.0625 + 0.01),
  # PSNR 10 log10(1 / 0.0625) = 12.041 dB.
  foreach(img "a;0.5" "b;0.25")
    list(GET img 0 name)
    list(GET img 1 v)
    execute_process(COMMAND "${OIIOTOOL}" --pattern "constant:color=${v},${v},${v}" 8x6 3
                            -d float --attrib "canopy:spp" 7 -o "${DIR}/${name}.exr"
                    RESULT_VARIABLE rc)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "oiiotool failed (${rc})")
    endif()
  endforeach()
  execute_process(COMMAND "${OIIOTOOL}" --pattern "constant:color=0,0,0" 4x4 3 -d float
                          -o "${DIR}/small.exr")

  run_canopy(0 compare "${DIR}/a.exr" "${DIR}/b.exr" --error-image "${DIR}/err.png")
  expect_contains("${out}" "RMSE       2.500000e-01")
  expect_contains("${out}" "relMSE     8.620690e-01")
  expect_contains("${out}" "PSNR       12.041 dB")
  expect_contains("${out}" "spp 7") # metadata read back
  if(NOT EXISTS "${DIR}/err.png")
    message(FATAL_ERROR "compare --error-image did not write ${DIR}/err.png")
  endif()
  run_canopy(0 compare "${DIR}/a.exr" "${DIR}/a.exr" --json)
  expect_contains("${out}" "\"rmse\": 0.0")
  expect_contains("${out}" "\"psnr\": \"inf\"")
  # --mask: the per-pixel MSE over all pixels and over those the mask leaves out. D is A with its
  # left half at 0.25 (squared error 0.0625 there), the mask white on that half.
  execute_process(COMMAND "${OIIOTOOL}" --pattern "constant:color=0.25,0.25,0.25" 4x6 3
                          "${DIR}/a.exr" --paste +0+0 -o "${DIR}/d.exr")
  execute_process(COMMAND "${OIIOTOOL}" --pattern "constant:color=1,1,1" 4x6 3
                          --pattern "constant:color=0,0,0" 8x6 3 --paste +0+0 -d uint8
                          -o "${DIR}/mask.png")
  run_canopy(0 compare "${DIR}/d.exr" "${DIR}/a.exr" --mask "${DIR}/mask.png")
  expect_contains("${out}" "pixel MSE  3.125000e-02 (all), 0.000000e+00 (the 24 pixels")
  run_canopy(2 compare "${DIR}/d.exr" "${DIR}/a.exr" --mask "${DIR}/small.exr")
  expect_contains("${err}" "${DIR}/small.exr: size differs from ${DIR}/a.exr (8x6)")
  # Invalid input: exit code 2 and one line naming the file.
  run_canopy(2 compare "${DIR}/a.exr" "${DIR}/missing.exr")
  expect_contains("${err}" "${DIR}/missing.exr: cannot read image")
  run_canopy(2 compare "${DIR}/a.exr" "${DIR}/small.exr")
  expect_contains("${err}" "${DIR}/small.exr: size 4x4 differs from ${DIR}/a.exr (8x6)")
elseif(MODE STREQUAL "converge")
  run_canopy(0 converge "${SCENE}" --reference "${DIR}/ref.exr" --reference-spp 64
             --reference-sampler tree-split
             --samplers power,tree,tree-noorient,tree-split:0.5,tree-split:0.5/nomis,auto
             --budget 2
             --seeds 2 --out "${DIR}/tiny")
  foreach(f tiny.csv tiny-median.csv tiny-configs.csv tiny-time.png tiny-rays.png ref.exr)
    if(NOT EXISTS "${DIR}/${f}")
      message(FATAL_ERROR "canopy converge did not write ${DIR}/${f}\nstdout:\n${out}")
    endif()
  endforeach()
  file(STRINGS "${DIR}/tiny.csv" rows)
  list(GET rows 0 header)
  expect_contains("${header}" "sampler,light_sampler,split_threshold,spp,seed,seconds,shadow_rays")
  foreach(s ",power,power," ",tree,tree," ",tree-noorient,tree," ",tree-split:0.5,tree-split,0.5,")
    expect_contains("${rows}" "${s}")
  endforeach()
  # The mis column (before max_depth, mode, timing_seconds, auto_choice, pilot_seconds): /nomis
  # renders with MIS off, every other configuration with MIS on; auto names the candidates its
  # explorations chose, with their counts.
  file(STRINGS "${DIR}/tiny-configs.csv" cfg_rows)
  foreach(re "^tiny_converge,tree-split:0.5/nomis,tree-split,0.5,.*,0,1,curve,[0-9.]+,,0.000$"
             "^tiny_converge,tree-split:0.5,tree-split,0.5,.*,1,1,curve,[0-9.]+,,0.000$"
             "^tiny_converge,power,power,.*,1,1,curve,[0-9.]+,,0.000$"
             "^tiny_converge,auto,auto,.*,1,1,curve,[0-9.]+,(power|tree|brdf-mis/split=0.25) x[0-9]+( (power|tree|brdf-mis/split=0.25) x[0-9]+)*,[0-9.]+$")
    set(hits ${cfg_rows})
    list(FILTER hits INCLUDE REGEX "${re}")
    list(LENGTH hits n)
    if(NOT n EQUAL 1)
      message(FATAL_ERROR "tiny-configs.csv: expected one row matching ${re}:\n${cfg_rows}")
    endif()
  endforeach()
  expect_contains("${out}" "equal-time RMSE")
  expect_contains("${err}" "light_sampler tree-split") # the reference's metadata, read back
  expect_contains("${header}" "max_depth,mode,mse,top_share,worst_pixel,mse_ne")
  if(NOT EXISTS "${DIR}/ref.mask.png")
    message(FATAL_ERROR "canopy converge did not write the emitter mask ${DIR}/ref.mask.png")
  endif()

  # Equal time at depth 1: a reference timed to ~2 s, 3 seeds of ~0.1 s per configuration (the
  # 8-seed minimum is make-results.sh's), then the reference reused at another depth (refused).
  run_canopy(0 converge "${SCENE}" --reference "${DIR}/ref1.exr" --reference-time 2
             --reference-sampler tree-split:0.5 --samplers power,tree-split --equal-time 0.1
             --seeds 3 --max-depth 1 --out "${DIR}/eq")
  file(STRINGS "${DIR}/eq-points.csv" pts)
  list(GET pts 0 pheader)
  foreach(col "mode,spp,runs,seconds" "mse,mse_lo,mse_hi,efficiency,efficiency_lo,efficiency_hi"
              "top_share_mean,top_share_max,worst_pixel_max,reference_floor,resolved"
              "mse_ne,mse_lo_ne,mse_hi_ne,efficiency_ne" "reference_floor_ne,resolved_ne")
    expect_contains("${pheader}" "${col}")
  endforeach()
  list(LENGTH pts n)
  if(NOT n EQUAL 3)
    message(FATAL_ERROR "eq-points.csv: expected a header and one row per configuration:\n${pts}")
  endif()
  foreach(re "^tiny_converge,power,power,[^,]*,1,1,equal-time,[1-9][0-9]*,3,"
             "^tiny_converge,tree-split,tree-split,[^,]*,1,1,equal-time,[1-9][0-9]*,3,")
    set(hits ${pts})
    list(FILTER hits INCLUDE REGEX "${re}")
    list(LENGTH hits nh)
    if(NOT nh EQUAL 1)
      message(FATAL_ERROR "eq-points.csv: expected one row matching ${re}:\n${pts}")
    endif()
  endforeach()
  expect_contains("${out}" "equal time 0.1 s, max depth 1, 3 seeds")
  expect_contains("${err}" "max_depth 1")
  expect_contains("${err}" "reference_mse_nonemitter")
  # A reference of another depth is invalid input.
  run_canopy(2 converge "${SCENE}" --reference "${DIR}/ref1.exr" --max-depth 2 --equal-time 0.1
             --seeds 1)
  expect_contains("${err}" "rendered with max depth 1, the measurements use 2")
  # A reference of the wrong size is invalid input.
  run_canopy(2 converge "${SCENE}" --reference "${DIR}/ref.exr" --film-scale 0.5 --budget 1)
  expect_contains("${err}" "${DIR}/ref.exr: size 32x24 differs from the render (16x12)")
  run_canopy(2 converge "${SCENE}" --reference "${DIR}/ref.exr" --samplers power,bogus)
  expect_contains("${err}" "--samplers: unknown light sampler 'bogus'")
  run_canopy(2 converge "${SCENE}" --reference "${DIR}/ref.exr" --samplers power-noorient)
  expect_contains("${err}" "--samplers: 'power-noorient': -noorient applies to tree samplers only")
elseif(MODE STREQUAL "merge")
  # stderr is exactly one line
  function(expect_one_line text)
    string(REGEX REPLACE "\n$" "" body "${text}")
    string(FIND "${body}" "\n" nl)
    if(NOT nl EQUAL -1 OR body STREQUAL "")
      message(FATAL_ERROR "expected exactly one line, got:\n${text}")
    endif()
  endfunction()
  run_canopy(0 render "${SCENE}" --spp 4 --out "${DIR}/full.exr")
  # --film-scale: the scene's film at half its resolution (a preview).
  run_canopy(0 render "${SCENE}" --film-scale 0.5 --spp 1 --out "${DIR}/half.exr")
  expect_contains("${err}" "16x12, 1 spp")
  run_canopy(0 render "${SCENE}" --samples 0:1 --out "${DIR}/a.exr")
  run_canopy(0 render "${SCENE}" --samples 1:4 --out "${DIR}/b.exr")
  expect_contains("${err}" "32x24, 3 spp (samples 1:4)")
  run_canopy(0 merge "${DIR}/m.exr" "${DIR}/a.exr" "${DIR}/b.exr")
  expect_contains("${out}" "merged 2 images into ${DIR}/m.exr: 32x24, 4 samples per pixel (samples 0:4 of seed 1)")
  run_canopy(0 compare "${DIR}/m.exr" "${DIR}/full.exr" --json)
  # Equal up to float rounding of the means.
  string(REGEX MATCH "\"max_abs_error\": ([^,]*)," m "${out}")
  if(NOT CMAKE_MATCH_1 OR NOT CMAKE_MATCH_1 LESS 1e-6)
    message(FATAL_ERROR "merged ranges differ from the one render:\n${out}")
  endif()
  # A merged image of one range is itself a partial render: it merges again.
  run_canopy(0 render "${SCENE}" --samples 4:6 --crop 0,0,16,24 --out "${DIR}/c.exr")
  expect_contains("${err}" "(samples 4:6), crop 0,0,16,24")
  run_canopy(0 merge "${DIR}/m2.exr" "${DIR}/m.exr" "${DIR}/c.exr")
  expect_contains("${out}" "6 samples per pixel")
  expect_contains("${out}" "missing coverage: 384 of 768 pixels have fewer samples (as few as 4) than the most covered (6)")
  # Refusals: exit 2, one line.
  run_canopy(2 merge "${DIR}/x.exr" "${DIR}/m.exr" "${DIR}/a.exr")
  expect_contains("${err}" "${DIR}/m.exr and ${DIR}/a.exr both hold samples [0, 1) of seed 1 for pixels [0, 32) x [0, 24)")
  expect_one_line("${err}")
  run_canopy(2 merge "${DIR}/x.exr" "${DIR}/a.exr" "${DIR}/missing.exr")
  expect_contains("${err}" "${DIR}/missing.exr: no such file")
  expect_one_line("${err}")
  run_canopy(0 render "${OTHER}" --samples 1:2 --out "${DIR}/other.exr")
  run_canopy(2 merge "${DIR}/x.exr" "${DIR}/a.exr" "${DIR}/other.exr")
  expect_contains("${err}" "${DIR}/other.exr: rendered from scene ${OTHER}")
  expect_one_line("${err}")
  run_canopy(2 merge "${DIR}/x.exr" "${DIR}/a.exr" "${DIR}/m2.exr")
  expect_contains("${err}" "${DIR}/m2.exr: not a Canopy render (no canopy:samples attribute")
  expect_one_line("${err}")
  run_canopy(2 merge "${DIR}/a.exr" "${DIR}/a.exr" "${DIR}/b.exr")
  expect_contains("${err}" "${DIR}/a.exr: is both an input and the output")
  run_canopy(2 render "${SCENE}" --samples 3:2 --out "${DIR}/y.exr")
  expect_contains("${err}" "--samples: '3:2': want A:B with 0 <= A < B <= 16777216")
  expect_one_line("${err}")
  run_canopy(2 render "${SCENE}" --samples 0:2 --spp 2 --out "${DIR}/y.exr")
  expect_contains("${err}" "--samples and --spp: give one")
  run_canopy(2 render "${SCENE}" --crop 0,0,33,24 --out "${DIR}/y.exr")
  expect_contains("${err}" "--crop: '0,0,33,24': want x0,y0,x1,y1 with 0 <= x0 < x1 <= 32 and 0 <= y0 < y1 <= 24 (the film)")
  expect_one_line("${err}")
  if(EXISTS "${DIR}/x.exr" OR EXISTS "${DIR}/y.exr")
    message(FATAL_ERROR "a refused merge or render wrote its output")
  endif()
  # Progress in a log (stderr is a pipe here): whole lines, no carriage returns; none with --quiet.
  run_canopy(0 render "${LONG}" --spp 32 --out "${DIR}/long.exr")
  expect_contains("${err}" "canopy: 100% rendered, ")
  string(FIND "${err}" "\r" cr)
  if(NOT cr EQUAL -1)
    message(FATAL_ERROR "progress wrote a carriage return into a log:\n${err}")
  endif()
  run_canopy(0 render "${LONG}" --spp 4 --quiet --out "${DIR}/long.exr")
  string(FIND "${err}" "rendered, " p)
  if(NOT p EQUAL -1)
    message(FATAL_ERROR "--quiet still reports progress:\n${err}")
  endif()
else()
  message(FATAL_ERROR "cli_tools.cmake: unknown MODE '${MODE}'")
endif()
