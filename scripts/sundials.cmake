# CMAKE_PROJECT_INCLUDE of the SUNDIALS build in scripts/setup.sh: arkode_butcher.c at -O1, not -O3.
# It is a seventh of the build's CPU at -O3 (7 s of 47), and pyspline's runs use only its table
# allocation, copy and free (ERKStep's tables are filled in arkode_butcher_erk.c, still -O3): its
# order-condition checks are never called. Same numbers (docs/building.md).
cmake_language(DEFER CALL set_source_files_properties
  "${CMAKE_SOURCE_DIR}/src/arkode/arkode_butcher.c" DIRECTORY "${CMAKE_SOURCE_DIR}/src/arkode"
  PROPERTIES COMPILE_OPTIONS -O1)
