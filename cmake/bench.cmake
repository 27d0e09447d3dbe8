# Benchmarks (Google Benchmark): every bench/bench_*.cpp becomes an executable linked to viper_core.
# Run with rosrun viper bench_NAME. Skipped quietly where libbenchmark-dev is not installed.
find_package(benchmark QUIET)
if(benchmark_FOUND)
  file(GLOB VIPER_BENCHES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/bench/bench_*.cpp)
  foreach(b ${VIPER_BENCHES})
    get_filename_component(name ${b} NAME_WE)
    add_executable(${name} ${b})
    target_link_libraries(${name} benchmark::benchmark viper_core)
    # bench_evaluate and bench_ground_truth read the package's class table.
    target_compile_definitions(${name} PRIVATE VIPER_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
    viper_bin_output(${name})
  endforeach()
  # The capture writer's frame finishing lives in the capture layer, not in viper_core.
  target_sources(bench_capture_finish PRIVATE ${PROJECT_SOURCE_DIR}/src/capture/layer/finish_frame.cpp)
  target_include_directories(bench_capture_finish PRIVATE ${PROJECT_SOURCE_DIR}/src/capture/layer)
else()
  message(STATUS "Google Benchmark not found: benchmarks are not built (apt install libbenchmark-dev)")
endif()
