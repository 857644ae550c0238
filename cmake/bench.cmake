# Benchmarks (make bench): bench/*.cpp -> bench_<name>, Google Benchmark, never run by tests.
find_package(benchmark QUIET)
file(GLOB DTM_BENCH_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/bench/*.cpp)
if(benchmark_FOUND AND DTM_BENCH_SOURCES)
  add_custom_target(benchmarks)
  foreach(bench_source ${DTM_BENCH_SOURCES})
    get_filename_component(bench ${bench_source} NAME_WE)
    add_executable(bench_${bench} EXCLUDE_FROM_ALL ${bench_source})
    target_link_libraries(bench_${bench} dtm_core benchmark::benchmark)
    target_compile_definitions(bench_${bench} PRIVATE
      DTM_SHARED_DATA_DIR="${DTM_SHARED_DATA_DIR}")
    add_dependencies(benchmarks bench_${bench})
  endforeach()
endif()
