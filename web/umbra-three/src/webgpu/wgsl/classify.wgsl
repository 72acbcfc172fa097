// The classify pass of umbra-three's WebGPU volumes (passes.js): after cs-silhouette's compute
// passes compacted one light's side quads (cs_sides.wgsl) and caps (orientation.wgsl), one
// invocation per volume polygon (polygon.wgsl's ids) sorts it: every vertex inside the
// viewport's planes (and the near plane, for a light cap) -> the `inside` list, drawn as it is
// (fan.wgsl vs_inside, 6 vertices); all outside one plane -> dropped (it covers no pixel
// centre); crossing a plane -> the `crossing` list, clipped where it is drawn (fan.wgsl
// vs_crossing, 18 vertices). Both lists are compacted with one atomicAdd on their draw
// command's vertex count.
// Prepended: `enable clip_distances;`, volume.wgsl, polygon.wgsl.

@group(1) @binding(0) var<storage, read> clip: array<vec4<f32>>;
@group(1) @binding(1) var<storage, read> quads: array<vec2<u32>>;
@group(1) @binding(2) var<storage, read> caps: array<u32>;
// The sides' and caps' draw commands the earlier passes filled: word 0 is the vertex count.
@group(1) @binding(3) var<storage, read> sides_command: array<u32, 4>;
@group(1) @binding(4) var<storage, read> caps_command: array<u32, 4>;
// [0] the inside polygons' draw (6 vertices each), [1] the crossing ones' (18 each).
@group(1) @binding(5) var<storage, read_write> fan_commands: array<DrawCommand, 2>;
// The inside list from 0, the crossing list from word `crossing_first` (below).
@group(1) @binding(6) var<storage, read_write> lists: array<u32>;

struct Classify {
    // First word of the crossing list in `lists` (the lists' capacity each).
    crossing_first: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}
@group(2) @binding(0) var<uniform> classify: Classify;

@compute @workgroup_size(256)
fn classify_polygons(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = umbra_item(gid, groups);
    let quads_n = sides_command[0] / 6u;
    let caps_n = caps_command[0] / u.vertices_per_cap;
    // Polygons per cap: the light cap, and the dark cap of a point light.
    let per_cap = u.vertices_per_cap / 3u;
    if i >= quads_n + caps_n * per_cap {
        return;
    }
    var id: u32;
    if i < quads_n {
        id = i << 2u;
    } else {
        let j = i - quads_n;
        id = ((j / per_cap) << 2u) | (1u + j % per_cap);
    }
    let sorted = umbra_classify(umbra_polygon(id));
    if sorted == 0u {
        lists[atomicAdd(&fan_commands[0].vertex_count, 6u) / 6u] = id;
    } else if sorted == 2u {
        lists[classify.crossing_first + atomicAdd(&fan_commands[1].vertex_count, 18u) / 18u] = id;
    }
}
