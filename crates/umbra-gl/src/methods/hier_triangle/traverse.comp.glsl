// hier-triangle, per light: the persistent traversal (Sintorn et al. 2014; one dispatch of
// Jobs::workgroups workgroups, LANES invocations each, a workgroup being one subgroup). A
// workgroup takes the next job from the atomic job counter (the list setup.comp.glsl made: the
// triangles whose frustum cuts a top node, in about the largest-first order, so that the large
// shadows clear whole nodes early and the many small triangles then skip them) and walks the
// hierarchy depth-first with it: a node's children are tested in parallel, one per invocation
// (two where LANES is 8, llvmpipe's vector width), against the triangle's shadow frustum
// (live.glsl test_child, frustum.glsl classify_node); the children it cuts form the node's
// mask, a subgroup ballot, pushed on the stack and entered one by one; a child wholly inside
// the shadow is cleared in the global live bitmask (live.glsl, atomicAnd), so later triangles
// never test it again; the leaf children of a node are tested where the node is, each
// invocation testing its samples exactly (test_sample) and clearing the bits of those
// shadowed. Only live children and samples are tested. When the stack empties the workgroup
// takes the next job; when the counter passes the last one it ends.
//
// Every invocation keeps its own copy of the stack and takes the same decisions (they depend
// only on the ballot and the job, which every invocation reads), so control flow stays uniform
// and no barrier is needed. llvmpipe ends a shader's loops silently after 65,535 iterations of
// all loops together (docs/exactness.md): there u_loop_budget is below that, each step counts
// the most iterations it can take (STEP_ITERATIONS), and a workgroup whose budget is spent
// saves its place (triangle, stack) in its slot and stops; the next dispatch resumes it
// (hier_triangle/mod.rs repeats the dispatch until no workgroup is left unfinished). Elsewhere
// the budget is unlimited: one dispatch. No loop nest of constant bounds (NVIDIA's compiler
// unrolls those without end). Prepended: hier/hierarchy.glsl, hier/region.glsl, frustum.glsl,
// live.glsl.

layout(local_size_x = LANES) in;

// The job buffer (hier_triangle/layout.rs Jobs): [0] the next job, [1] workgroups the dispatch
// left unfinished, [2] jobs in the list; the order; the list (per job: triangle, mask of the
// top nodes its frustum cuts); then one slot of SLOT_WORDS per workgroup: triangle + 1 (0:
// idle), stack depth, stack nodes, stack masks.
layout(std430, binding = 8) coherent buffer Jobs { uint jobs[]; };

// Where the job list (setup.comp.glsl) begins.
uniform uint u_jobs_list;
uniform uint u_slots_offset;
// Loop iterations a workgroup may spend in this dispatch (0xFFFFFFFF: no limit).
uniform uint u_loop_budget;

const uint STACK = MAX_LEVELS + 1u;
// Loop iterations one step may take, at most, as llvmpipe's limiter counts them (a loop under a
// mask with no invocation in it still counts its first iteration): the step itself, clear_node's
// (MAX_LEVELS) at the two child tests and the pops (STACK); and per leaf tested in the step
// (LEAF_ITERATIONS) one iteration of the leaves' loop and clear_node's at its two sample tests.
const uint STEP_ITERATIONS = 1u + 2u * uint(MAX_LEVELS) + STACK;
const uint LEAF_ITERATIONS = 1u + 2u * uint(MAX_LEVELS);

void main() {
    uint lane = gl_LocalInvocationIndex;
    uint slot = u_slots_offset + gl_WorkGroupID.x * SLOT_WORDS;
    // The place this workgroup's last dispatch left (idle after init.comp.glsl).
    uint tri1 = jobs[slot];
    uint depth = jobs[slot + 1u];
    uint st_node[STACK];
    uint st_mask[STACK];
    for (uint j = 0u; j < STACK; ++j) {
        st_node[j] = jobs[slot + 2u + j];
        st_mask[j] = jobs[slot + 2u + STACK + j];
    }
    Frustum f;
    if (tri1 != 0u) {
        f = load_frustum(tri1 - 1u);
    }
    // The stack's and the frustum's loads above, counted as iterations.
    uint spent = 2u * STACK + 9u;
    bool finished = false;
    for (uint step = 0u; step < 0xFFFFFFFFu; ++step) {
        uint taken = 0u;
        uint m = 0u;
        uint level = 0u;
        uint node = 0u;
        if (tri1 == 0u) {
            // Idle: invocation 0 takes the next job.
            if (lane == 0u) {
                taken = atomicAdd(jobs[0], 1u);
            }
        } else {
            // The next child of the node on top of the stack (entry d holds a node at level
            // u_levels - d; pops below keep a set bit on top): its children against the
            // triangle.
            uint d = depth - 1u;
            uint k = findLSB(st_mask[d]);
            st_mask[d] &= ~(1u << k);
            level = u_levels - d - 1u;
            live_child(level + 1u, st_node[d], k, node);
            bool cut0 = test_child(f, level, node, lane);
            bool cut1 = false;
#if LANES < 16
            cut1 = test_child(f, level, node, lane + LANES);
#endif
            // The cut children's mask: one ballot per half (the workgroup is one subgroup).
            m = unpackUint2x32(ballotARB(cut0)).x | (unpackUint2x32(ballotARB(cut1)).x << LANES);
            if (level == 1u) {
                // Its children are leaves: their live samples are tested here, leaf by leaf.
                count_work(WORK_LEAVES_TESTED, lane == 0u ? uint(bitCount(m)) : 0u);
                spent += uint(bitCount(m)) * LEAF_ITERATIONS;
                for (uint left = m; left != 0u; left &= left - 1u) {
                    uint leaf;
                    child_of(1u, node, uint(findLSB(left)), leaf);
                    test_sample(tri1 - 1u, leaf, lane);
#if LANES < 16
                    test_sample(tri1 - 1u, leaf, lane + LANES);
#endif
                }
                m = 0u;
            }
        }
        spent += STEP_ITERATIONS;
        // Invocation 0's job, in every invocation.
        uint job = readInvocationARB(taken, 0u);
        if (tri1 == 0u) {
            if (job >= jobs[2]) {
                finished = true;
                break;
            }
            // The job: a triangle whose frustum cuts the top nodes in its mask (setup).
            uint tri = jobs[u_jobs_list + 2u * job];
            f = load_frustum(tri);
            spent += 9u;
            tri1 = tri + 1u;
            depth = 1u;
            st_node[0] = 0u;
            st_mask[0] = jobs[u_jobs_list + 2u * job + 1u];
        } else if (m != 0u) {
            st_node[depth] = node;
            st_mask[depth] = m;
            depth += 1u;
        }
        // Entries with no child left are done.
        while (depth > 0u && st_mask[depth - 1u] == 0u) {
            depth -= 1u;
        }
        if (depth == 0u) {
            tri1 = 0u;
        }
        // The same in every invocation (each counts the same steps): a uniform exit.
        if (spent > u_loop_budget) {
            break;
        }
    }
    if (lane != 0u) {
        return;
    }
    // Where this workgroup stands, for the next dispatch; and whether one is needed.
    jobs[slot] = finished ? 0u : tri1;
    jobs[slot + 1u] = depth;
    for (uint j = 0u; j < STACK; ++j) {
        jobs[slot + 2u + j] = st_node[j];
        jobs[slot + 2u + STACK + j] = st_mask[j];
    }
    if (!finished) {
        atomicAdd(jobs[1], 1u);
    }
}
