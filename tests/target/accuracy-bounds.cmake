# tests/target/accuracy-bounds.cmake: reads tests/target/accuracy-bounds.txt
# (the one place for the targets' accuracy bounds; toolchain/target-info bound
# reads it for the scripts).
#
# ascorr_read_accuracy_bounds() sets, in the caller's scope, ASCORR_BOUND_<scalar>
# (arcsec) for each scalar of the file; a malformed line or a missing fixed or
# float bound stops the configuration, naming the file.
if(NOT ASCORR_ACCURACY_BOUNDS)  # another file only in read-accuracy-bounds.cmake's tests
  set(ASCORR_ACCURACY_BOUNDS ${CMAKE_CURRENT_LIST_DIR}/accuracy-bounds.txt)
endif()

function(ascorr_read_accuracy_bounds)
  file(STRINGS ${ASCORR_ACCURACY_BOUNDS} lines REGEX "^[^#]")
  foreach(line ${lines})
    if(NOT line MATCHES "^([a-z]+) +([0-9]+(\\.[0-9]+)?)$")
      message(FATAL_ERROR "${ASCORR_ACCURACY_BOUNDS}: not 'scalar bound_arcsec': ${line}")
    endif()
    set(ASCORR_BOUND_${CMAKE_MATCH_1} ${CMAKE_MATCH_2} PARENT_SCOPE)
    set(seen_${CMAKE_MATCH_1} ON)
  endforeach()
  foreach(scalar fixed float)
    if(NOT seen_${scalar})
      message(FATAL_ERROR "${ASCORR_ACCURACY_BOUNDS}: no bound for ${scalar}")
    endif()
  endforeach()
  if(NOT CMAKE_SCRIPT_MODE_FILE)
    set_property(DIRECTORY ${PROJECT_SOURCE_DIR} APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${ASCORR_ACCURACY_BOUNDS})
  endif()
endfunction()
