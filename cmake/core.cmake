# The ROS-free core: one library per area (src/<area>, include/dormant_tree_modeling/<area>),
# each linking only the areas it may use. This table is the dependency graph of
# docs/architecture.md; scripts/check_layering.sh reads it and fails on any include outside it,
# and shared libraries are linked with --no-undefined so an undeclared use does not link either.
# Links Eigen, PCL, Boost and nlohmann_json only; no area may include ROS.
set(DTM_AREA_DEPS_common "")
set(DTM_AREA_DEPS_geometry common)
set(DTM_AREA_DEPS_modeling common)
set(DTM_AREA_DEPS_evaluation common modeling)
set(DTM_AREA_DEPS_io common modeling evaluation)
set(DTM_AREA_DEPS_registration common modeling io)
set(DTM_AREA_DEPS_calibration common modeling evaluation io registration)
set(DTM_AREA_DEPS_acquisition common geometry)
set(DTM_AREA_DEPS_lms111 common)
set(DTM_AREA_DEPS_aerotech common geometry)
set(DTM_AREA_DEPS_emulation common lms111 aerotech)
set(DTM_AREA_DEPS_simulation common geometry modeling evaluation io acquisition lms111 aerotech
    emulation)
# The areas the real system is made of; emulation and simulation (the virtual platform) are
# linked only by tools, tests, benchmarks and the virtual-platform node.
set(DTM_CORE_AREAS common geometry modeling evaluation io registration calibration acquisition
    lms111 aerotech)
set(DTM_VIRTUAL_AREAS emulation simulation)

if(CMAKE_SYSTEM_NAME STREQUAL "Linux")
  set(DTM_NO_UNDEFINED -Wl,--no-undefined)
endif()

foreach(area ${DTM_CORE_AREAS} ${DTM_VIRTUAL_AREAS})
  file(GLOB area_sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/${area}/*.cpp)
  add_library(dtm_${area} ${area_sources})
  target_include_directories(dtm_${area} PUBLIC ${PROJECT_SOURCE_DIR}/include)
  target_include_directories(dtm_${area} SYSTEM PUBLIC ${EIGEN3_INCLUDE_DIRS} ${PCL_INCLUDE_DIRS})
  target_compile_definitions(dtm_${area} PUBLIC ${PCL_DEFINITIONS})
  set(area_links "")
  foreach(dep ${DTM_AREA_DEPS_${area}})
    list(APPEND area_links dtm_${dep})
  endforeach()
  target_link_libraries(dtm_${area} PUBLIC ${area_links} ${PCL_LIBRARIES} Boost::system
                        Boost::thread Threads::Threads PRIVATE nlohmann_json::nlohmann_json
                        yaml-cpp ${STB_LIBRARY} ${DTM_NO_UNDEFINED})
  set_target_properties(dtm_${area} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endforeach()

# dtm_core: the real system's areas together, for the ROS layer; dtm_virtual adds the emulators
# and the simulated platform, for tools, tests and benchmarks.
add_library(dtm_core INTERFACE)
foreach(area ${DTM_CORE_AREAS})
  target_link_libraries(dtm_core INTERFACE dtm_${area})
endforeach()
add_library(dtm_virtual INTERFACE)
target_link_libraries(dtm_virtual INTERFACE dtm_core dtm_emulation dtm_simulation)

# Command-line tools (src/tools/<name>.cpp -> <name>), ROS-free.
file(GLOB DTM_TOOL_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/tools/*.cpp)
foreach(tool_source ${DTM_TOOL_SOURCES})
  get_filename_component(tool ${tool_source} NAME_WE)
  add_executable(${tool} ${tool_source})
  target_link_libraries(${tool} dtm_virtual Boost::program_options)
  install(TARGETS ${tool} RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
endforeach()

foreach(area ${DTM_CORE_AREAS} ${DTM_VIRTUAL_AREAS})
  install(TARGETS dtm_${area}
    ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
    LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
endforeach()
install(DIRECTORY include/${PROJECT_NAME}/ DESTINATION ${CATKIN_PACKAGE_INCLUDE_DESTINATION})
