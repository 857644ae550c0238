# The ROS layer: node classes (src/ros) in one library, one thin main per node (src/nodes).
file(GLOB DTM_ROS_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/ros/*.cpp)
add_library(dtm_ros ${DTM_ROS_SOURCES})
target_include_directories(dtm_ros SYSTEM PUBLIC ${catkin_INCLUDE_DIRS}
                           ${DTM_ROSBAG_INCLUDE_DIRS})
target_link_libraries(dtm_ros PUBLIC dtm_core ${catkin_LIBRARIES} ${ROSBAG_LIBRARY}
                      ${ROSBAG_STORAGE_LIBRARY} ${TOPIC_TOOLS_LIBRARY})
add_dependencies(dtm_ros ${PROJECT_NAME}_generate_messages_cpp ${catkin_EXPORTED_TARGETS})

file(GLOB DTM_NODE_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/nodes/*_node.cpp)
foreach(node_source ${DTM_NODE_SOURCES})
  get_filename_component(node_file ${node_source} NAME_WE)
  string(REGEX REPLACE "_node$" "" node ${node_file})
  add_executable(${node} ${node_source})
  target_link_libraries(${node} dtm_ros)
  install(TARGETS ${node} RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
endforeach()

install(TARGETS dtm_ros
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
install(DIRECTORY launch config rviz DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})
