# Installs the built library into a scratch prefix, then configures, builds and runs the
# consumer project against it. Fails on any error or a wrong answer. With WITH_DOMAINS, the
# consumer uses the domains component too; without, the consumer is configured with Eigen
# disabled, which proves that the core's package and headers need no Eigen.
file(REMOVE_RECURSE "${SCRATCH_DIR}")
execute_process(COMMAND "${CMAKE_COMMAND}" --install "${ONTIME_BUILD_DIR}" --prefix "${SCRATCH_DIR}/prefix"
  RESULT_VARIABLE status OUTPUT_QUIET)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "cmake --install failed: ${status}")
endif()
if(WITH_DOMAINS)
  set(component_options -DWITH_DOMAINS=ON)
else()
  set(component_options -DWITH_DOMAINS=OFF -DCMAKE_DISABLE_FIND_PACKAGE_Eigen3=ON)
endif()
execute_process(COMMAND "${CMAKE_COMMAND}" -S "${CONSUMER_SOURCE_DIR}" -B "${SCRATCH_DIR}/build" -G "${GENERATOR}"
  "-DCMAKE_PREFIX_PATH=${SCRATCH_DIR}/prefix" -DCMAKE_BUILD_TYPE=Release ${component_options}
  RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "configuring the consumer failed:\n${out}\n${err}")
endif()
execute_process(COMMAND "${CMAKE_COMMAND}" --build "${SCRATCH_DIR}/build"
  RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "building the consumer failed:\n${out}\n${err}")
endif()
execute_process(COMMAND "${SCRATCH_DIR}/build/consumer" "${INSTANCE}" RESULT_VARIABLE status OUTPUT_VARIABLE out)
if(NOT status EQUAL 0 OR NOT out STREQUAL "optimum 0.5625\n")
  message(FATAL_ERROR "consumer answered '${out}' (exit ${status}), expected 'optimum 0.5625'")
endif()
message(STATUS "consumer built against the installed package: ${out}")
if(WITH_DOMAINS)
  execute_process(COMMAND "${SCRATCH_DIR}/build/domains_consumer" navigation "${DOMAIN_WORLD}"
    RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT status EQUAL 0 OR NOT out STREQUAL "skeletons 4\n")
    message(FATAL_ERROR "domains consumer answered '${out}${err}' (exit ${status}), expected 'skeletons 4'")
  endif()
  message(STATUS "domains consumer built against the installed package: ${out}")
  # The installed ontime finds the world file and instance installed beside it (not the source
  # tree's data/, though that exists here), whatever the prefix.
  set(data "${SCRATCH_DIR}/prefix/share/ontime/data")
  execute_process(COMMAND "${CMAKE_COMMAND}" -E env --unset=ONTIME_DATA_DIR
    "${SCRATCH_DIR}/prefix/bin/ontime" run --domain navigation --solver dp --episodes 1 --threads 1 --json
    WORKING_DIRECTORY "${SCRATCH_DIR}" RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  string(FIND "${out}" "\"instance\": \"${data}/instances/navigation.json\"" at)
  if(NOT status EQUAL 0 OR at EQUAL -1)
    message(FATAL_ERROR "the installed ontime run answered '${out}${err}' (exit ${status})")
  endif()
  message(STATUS "the installed ontime runs on its installed data")
endif()
