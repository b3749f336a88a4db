# tests/target/read-accuracy-bounds.cmake (cmake -P): reads the accuracy bounds
# as the build does (accuracy-bounds.cmake; -DASCORR_ACCURACY_BOUNDS=FILE for
# another file) and prints them.
include(${CMAKE_CURRENT_LIST_DIR}/accuracy-bounds.cmake)
ascorr_read_accuracy_bounds()
message("bounds: fixed ${ASCORR_BOUND_fixed} float ${ASCORR_BOUND_float}")
