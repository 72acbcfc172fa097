// ray-bvh, per light and resume pass, one invocation: the DispatchIndirectCommand of the pass
// that continues the rays of list u_list_in (64 per workgroup, the groups laid out in rows of at
// most 65,535: GL_MAX_COMPUTE_WORK_GROUP_COUNT's guaranteed minimum per dimension), and the
// other list emptied for the rays that pass leaves unfinished.

#version 450 core

layout(local_size_x = 1) in;

// Words [4 l, 4 l + 4): list l's count and its dispatch command; the lists follow (trace.glsl).
layout(std430, binding = 7) buffer Lists { uint lists[]; };

uniform uint u_list_in;

void main() {
    uint groups = (lists[4u * u_list_in] + 63u) / 64u;
    uint rows = (groups + 65534u) / 65535u;
    lists[4u * u_list_in + 1u] = rows > 1u ? 65535u : groups;
    lists[4u * u_list_in + 2u] = rows;
    lists[4u * u_list_in + 3u] = 1u;
    lists[4u * (1u - u_list_in)] = 0u;
}
