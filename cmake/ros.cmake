# The ROS layer: node classes (src/ros) in one library, one thin main per node (src/nodes).
# The virtual platform's node class is the only one that uses the emulators and the simulation,
# so it has a library of its own and the real nodes never link them.
set(DTM_VIRTUAL_ROS_SOURCES ${PROJECT_SOURCE_DIR}/src/ros/virtual_platform_node.cpp)
file(GLOB DTM_ROS_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/ros/*.cpp)
list(REMOVE_ITEM DTM_ROS_SOURCES ${DTM_VIRTUAL_ROS_SOURCES})
add_library(dtm_ros ${DTM_ROS_SOURCES})
target_include_directories(dtm_ros SYSTEM PUBLIC ${catkin_INCLUDE_DIRS}
                           ${DTM_ROSBAG_INCLUDE_DIRS})
target_link_libraries(dtm_ros PUBLIC dtm_core ${catkin_LIBRARIES} ${ROSBAG_LIBRARY}
                      ${ROSBAG_STORAGE_LIBRARY} ${TOPIC_TOOLS_LIBRARY})
add_dependencies(dtm_ros ${PROJECT_NAME}_generate_messages_cpp ${catkin_EXPORTED_TARGETS})
add_library(dtm_ros_virtual ${DTM_VIRTUAL_ROS_SOURCES})
target_link_libraries(dtm_ros_virtual PUBLIC dtm_ros dtm_virtual)

file(GLOB DTM_NODE_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/nodes/*_node.cpp)
foreach(node_source ${DTM_NODE_SOURCES})
  get_filename_component(node_file ${node_source} NAME_WE)
  string(REGEX REPLACE "_node$" "" node ${node_file})
  add_executable(${node} ${node_source})
  if(node STREQUAL "virtual_platform")
    target_link_libraries(${node} dtm_ros_virtual)
  else()
    target_link_libraries(${node} dtm_ros)
  endif()
  install(TARGETS ${node} RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
endforeach()

install(TARGETS dtm_ros dtm_ros_virtual
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
install(DIRECTORY launch config rviz DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})
