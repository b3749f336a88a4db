# tests/target/read-target-table.cmake (cmake -P): reads the target table as
# the build does (toolchain/target-table.cmake; -DASCORR_TARGET_TABLE=FILE for
# another table) and prints its cpus and boards.
include(${CMAKE_CURRENT_LIST_DIR}/../../toolchain/target-table.cmake)
ascorr_read_targets()
set(boards "")
foreach(t ${ASCORR_TARGET_LIST})
  list(APPEND boards ${ASCORR_TARGET_${t}_MACHINE})
endforeach()
message("targets: ${ASCORR_TARGET_LIST}, boards ${boards}")
