# toolchain/target-table.cmake: reads toolchain/targets.txt (the one place for
# each Cortex-M target's facts; its header says what each column is).
#
# ascorr_read_targets() sets, in the caller's scope:
#   ASCORR_TARGET_LIST                 the cpus, in the table's order
#   ASCORR_TARGET_<cpu>_MACHINE        QEMU board
#   ASCORR_TARGET_<cpu>_SCALAR         flight/link image scalar (fixed or float)
#   ASCORR_TARGET_<cpu>_SCALARS        accuracy image scalars (a list)
#   ASCORR_TARGET_<cpu>_REPLAY         `ascorr replay --target` name
#   ASCORR_TARGET_<cpu>_FLAGS          compiler CPU flags
# A malformed line stops the configuration, naming the file and line.
if(NOT ASCORR_TARGET_TABLE)  # another table only in tests/target/read-target-table.cmake's tests
  set(ASCORR_TARGET_TABLE ${CMAKE_CURRENT_LIST_DIR}/targets.txt)
endif()

function(ascorr_read_targets)
  file(READ ${ASCORR_TARGET_TABLE} text)
  string(REPLACE ";" "," text "${text}")  # no list separator inside a line (none is valid in a row)
  string(REPLACE "\n" ";" lines "${text}")  # one element per line, empty lines kept (line numbers)
  set(list "")
  set(n 0)
  foreach(line IN LISTS lines)
    math(EXPR n "${n} + 1")
    if(line MATCHES "^#" OR line MATCHES "^[ \t]*$")
      continue()
    endif()
    if(NOT line MATCHES "^([a-z0-9-]+) +([a-z0-9-]+) +(fixed|float) +([a-z,]+) +([a-z0-9-]+) +(-.*)$")
      message(FATAL_ERROR "${ASCORR_TARGET_TABLE}:${n}: not 'cpu machine flight_scalar(fixed|float) "
                          "accuracy_scalars replay_target flags': ${line}")
    endif()
    set(cpu ${CMAKE_MATCH_1})
    string(REPLACE "," ";" scalars "${CMAKE_MATCH_4}")
    list(APPEND list ${cpu})
    set(ASCORR_TARGET_${cpu}_MACHINE ${CMAKE_MATCH_2} PARENT_SCOPE)
    set(ASCORR_TARGET_${cpu}_SCALAR ${CMAKE_MATCH_3} PARENT_SCOPE)
    set(ASCORR_TARGET_${cpu}_SCALARS "${scalars}" PARENT_SCOPE)
    set(ASCORR_TARGET_${cpu}_REPLAY ${CMAKE_MATCH_5} PARENT_SCOPE)
    set(ASCORR_TARGET_${cpu}_FLAGS "${CMAKE_MATCH_6}" PARENT_SCOPE)
  endforeach()
  set(ASCORR_TARGET_LIST ${list} PARENT_SCOPE)
endfunction()
