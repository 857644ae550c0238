# The ROS-free core library: every algorithm and protocol. Links Eigen, PCL, Boost and
# nlohmann_json only; scripts/check_layering.sh fails the build's lint step on any ROS include.
set(DTM_CORE_AREAS common io modeling evaluation simulation lms111 aerotech acquisition registration)
set(DTM_CORE_SOURCES "")
foreach(area ${DTM_CORE_AREAS})
  file(GLOB area_sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/${area}/*.cpp)
  list(APPEND DTM_CORE_SOURCES ${area_sources})
endforeach()

add_library(dtm_core ${DTM_CORE_SOURCES})
target_include_directories(dtm_core PUBLIC ${PROJECT_SOURCE_DIR}/include)
target_include_directories(dtm_core SYSTEM PUBLIC ${EIGEN3_INCLUDE_DIRS} ${PCL_INCLUDE_DIRS})
target_compile_definitions(dtm_core PUBLIC ${PCL_DEFINITIONS})
target_link_libraries(dtm_core PUBLIC ${PCL_LIBRARIES} Boost::system Boost::thread
                      Threads::Threads PRIVATE nlohmann_json::nlohmann_json yaml-cpp ${STB_LIBRARY})
set_target_properties(dtm_core PROPERTIES POSITION_INDEPENDENT_CODE ON)

# Command-line tools (src/tools/<name>.cpp -> <name>), ROS-free.
file(GLOB DTM_TOOL_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/tools/*.cpp)
foreach(tool_source ${DTM_TOOL_SOURCES})
  get_filename_component(tool ${tool_source} NAME_WE)
  add_executable(${tool} ${tool_source})
  target_link_libraries(${tool} dtm_core Boost::program_options)
  install(TARGETS ${tool} RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
endforeach()

install(TARGETS dtm_core
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
install(DIRECTORY include/${PROJECT_NAME}/ DESTINATION ${CATKIN_PACKAGE_INCLUDE_DESTINATION})
