// When a light may be counted z-pass, for both of umbra-three's paths (umbra-shadows.js on
// WebGL 2, webgpu/umbra-shadows-webgpu.js): the eye's near pyramid tested against each caster
// (crates/umbra-wasm/src/clearance.rs, through the wasm), and the unions of casters that share
// one space, kept between frames.

/** Frames a z-pass union (UnionCache.of) is kept after the last frame that asked for it. */
const UNION_FRAMES = 600;

/**
 * The stencil start of light `k` under z-pass, sum(W0) mod 256 (8-bit stencil, wrapping
 * counts; negative for a negative sum), when every caster's test proves one count W0 for the eye's whole near pyramid;
 * null (z-fail) when any caster cannot (or has no points: z-pass off, projective matrix).
 * Casters that share a world matrix (`group`, one space) are asked together when one of them
 * cannot answer alone: the test of their union (`unionOf(group)`, UnionCache.of;
 * crates/umbra-wasm/src/clearance.rs), whose W0 is the sum the stencil counts (a loader's groups of one model have
 * open borders that the union closes).
 */
export function zpassStart(tests, k, unionOf) {
  const groups = new Map();
  for (const t of tests) {
    if (!t.points) return null;
    if (!groups.has(t.group)) groups.set(t.group, []);
    groups.get(t.group).push(t);
  }
  let sum = 0;
  for (const group of groups.values()) {
    let w = 0;
    for (const t of group) {
      const w0 = t.caster.nearWinding(t.points, t.lights[k]);
      if (w0 === null) {
        w = null;
        break;
      }
      w += w0;
    }
    // The same matrix: the same points and light in the group's space.
    if (w === null && group.length > 1) w = unionOf(group).nearWinding(group[0].points, group[0].lights[k]);
    if (w === null) return null;
    sum += w;
  }
  return sum % 256;
}

/**
 * The z-pass tests of unions of casters (`geom.union`, crates/umbra-wasm/src/clearance.rs), by
 * their casters' keys: built once per set of geometry versions, freed when no frame asked for
 * them in the last UNION_FRAMES frames (a moving camera needs a group's union in one frame and
 * not the next: building it again cost Sponza 50-160 ms of main thread a time).
 */
export class UnionCache {
  constructor(geom) {
    this.geom = geom;
    this.unions = new Map();
  }

  /** The union of `tests`' casters (each `{ caster, key }`), asked in frame `frame`. */
  of(tests, frame) {
    const key = tests.map((t) => t.key).sort().join('|');
    let u = this.unions.get(key);
    if (!u) {
      u = { union: this.geom.union(tests.map((t) => t.caster)), frame };
      this.unions.set(key, u);
    }
    u.frame = frame;
    return u.union;
  }

  /** Frees the unions no frame asked for since `frame - UNION_FRAMES`. */
  prune(frame) {
    for (const [key, u] of this.unions) {
      if (frame - u.frame >= UNION_FRAMES) {
        u.union.free();
        this.unions.delete(key);
      }
    }
  }

  /** How many unions are kept. */
  get size() {
    return this.unions.size;
  }

  /** Frees every union. */
  clear() {
    for (const u of this.unions.values()) u.union.free();
    this.unions.clear();
  }
}
