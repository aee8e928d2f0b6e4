# The image outputs appear only by rename(2): a render to an existing path never writes into the
# existing file. A hard link ("witness") to the first render's EXR and PNG must keep the first
# image byte for byte after a second render (another seed) to the same paths, while the paths
# themselves show the new image; no temporary file is left behind. An in-place write (which
# two concurrent renders, or SIGINT during the write, turn into a corrupt or lost file) changes
# the witness.
#   cmake -DEXE=<canopy> -DSCENE=<file> -DDIR=<scratch dir> -P check_output_atomic.cmake
file(REMOVE_RECURSE "${DIR}")
file(MAKE_DIRECTORY "${DIR}")
function(render seed)
  execute_process(
    COMMAND "${EXE}" render "${SCENE}" --spp 1 --seed ${seed} --out "${DIR}/img.exr"
    RESULT_VARIABLE rc
    ERROR_VARIABLE err
    OUTPUT_QUIET
    TIMEOUT 120)
  if(NOT rc STREQUAL "0")
    message(FATAL_ERROR "render (seed ${seed}) failed: ${rc}\n${err}")
  endif()
endfunction()
render(1)
foreach(ext exr png)
  file(CREATE_LINK "${DIR}/img.${ext}" "${DIR}/witness.${ext}")
  file(SHA256 "${DIR}/img.${ext}" first_${ext})
endforeach()
render(2)
foreach(ext exr png)
  file(SHA256 "${DIR}/witness.${ext}" witness)
  file(SHA256 "${DIR}/img.${ext}" second)
  if(NOT witness STREQUAL first_${ext})
    message(FATAL_ERROR "img.${ext} was rewritten in place: the old file's content changed")
  endif()
  if(second STREQUAL first_${ext})
    message(FATAL_ERROR "img.${ext} still holds the first image (the seed made no difference?)")
  endif()
endforeach()
file(GLOB leftovers "${DIR}/.*")
if(leftovers)
  message(FATAL_ERROR "temporary files left behind: ${leftovers}")
endif()
file(REMOVE_RECURSE "${DIR}")
