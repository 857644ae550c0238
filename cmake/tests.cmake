# Unit tests: one gtest executable per test/unit/test_*.cpp, linked against the core and the virtual platform.
# Node tests: one rostest per test/rostest/*.test, with its gtest node from test/rostest/*.cpp.
find_package(rostest REQUIRED)

file(GLOB DTM_UNIT_TESTS CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/test/unit/test_*.cpp)
foreach(test_source ${DTM_UNIT_TESTS})
  get_filename_component(test_name ${test_source} NAME_WE)
  catkin_add_gtest(${test_name} ${test_source})
  target_link_libraries(${test_name} dtm_virtual ${GTEST_MAIN_LIBRARIES})
  target_compile_definitions(${test_name} PRIVATE
    DTM_TEST_DATA_DIR="${DTM_TEST_DATA_DIR}" DTM_SHARED_DATA_DIR="${DTM_SHARED_DATA_DIR}"
    DTM_CONFIG_DIR="${PROJECT_SOURCE_DIR}/config" DTM_TOOL_DIR="${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION}")
endforeach()
# The tool tests run the built tools.
if(TARGET test_tools)
  add_dependencies(test_tools tree_model evaluate_model lms111_decode render_model synth_tree
                   calibrate_diameters lms111_emulator aerotech_emulator)
endif()

file(GLOB DTM_ROSTEST_NODES
 CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/test/rostest/*.cpp)
foreach(test_source ${DTM_ROSTEST_NODES})
  get_filename_component(test_name ${test_source} NAME_WE)
  add_executable(${test_name} EXCLUDE_FROM_ALL ${test_source})
  target_link_libraries(${test_name} dtm_ros dtm_virtual ${GTEST_LIBRARIES})
  target_include_directories(${test_name} SYSTEM PRIVATE ${GTEST_INCLUDE_DIRS})
  target_compile_definitions(${test_name} PRIVATE
    DTM_TEST_DATA_DIR="${DTM_TEST_DATA_DIR}" DTM_SHARED_DATA_DIR="${DTM_SHARED_DATA_DIR}"
    DTM_BIN_DIR="${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION}"
    DTM_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  add_dependencies(tests ${test_name})
endforeach()

# The driver's node test runs the emulator.
if(TARGET test_lms111_driver_node)
  add_dependencies(test_lms111_driver_node lms111_emulator lms111_driver)
endif()
if(TARGET test_acquisition_node)
  add_dependencies(test_acquisition_node virtual_platform lms111_driver stage_controller
                   scan_assembler acquisition)
endif()
if(TARGET test_view_acquisition)
  add_dependencies(test_view_acquisition virtual_platform lms111_driver stage_controller
                   scan_assembler)
endif()
if(TARGET test_stage_controller_node)
  add_dependencies(test_stage_controller_node aerotech_emulator stage_controller)
endif()
if(TARGET test_stage_controller_backoff)
  add_dependencies(test_stage_controller_backoff stage_controller)
endif()

file(GLOB DTM_ROSTESTS CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/test/rostest/*.test)
foreach(launch_file ${DTM_ROSTESTS})
  file(RELATIVE_PATH rel ${PROJECT_SOURCE_DIR} ${launch_file})
  add_rostest(${rel})
endforeach()

# Every launch file passes roslaunch-check (arguments resolve, nodes and packages exist).
find_package(roslaunch REQUIRED)
file(GLOB DTM_LAUNCH_FILES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/launch/*.launch)
foreach(launch_file ${DTM_LAUNCH_FILES})
  file(RELATIVE_PATH rel ${PROJECT_SOURCE_DIR} ${launch_file})
  if(rel STREQUAL "launch/model_file.launch")
    roslaunch_add_file_check(${rel} file:=tree.pcd)
  elseif(rel STREQUAL "launch/replay.launch")
    roslaunch_add_file_check(${rel} bag:=tree.bag)
  else()
    roslaunch_add_file_check(${rel})
  endif()
endforeach()

# The whole-system tests run every node; the rviz test runs the modeler.
if(TARGET test_end_to_end)
  add_dependencies(test_end_to_end virtual_platform lms111_driver stage_controller scan_assembler
                   acquisition registration tree_modeler)
endif()
if(TARGET test_replay)
  add_dependencies(test_replay scan_assembler registration tree_modeler)
endif()
if(TARGET test_replay_bag)
  add_dependencies(test_replay_bag scan_assembler registration tree_modeler)
endif()
if(TARGET test_rviz_screenshot)
  add_dependencies(test_rviz_screenshot tree_modeler)
endif()
