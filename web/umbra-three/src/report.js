// The error log both UmbraShadows classes (WebGL 2, WebGPU) keep: nothing is thrown inside
// render(); a refused mesh, light or frame is an entry { mesh, message } in `owner.errors`,
// once per (object, message), and `owner.onError` is called with it.

/** Adds `message` about `object` (a name or uuid) to `owner.errors` once, and calls `owner.onError`. */
export function reportOnce(owner, object, message) {
  // The entry names the object; its message need not repeat it.
  if (message.startsWith(`${object}: `)) message = message.slice(object.length + 2);
  const key = `${object}\u0000${message}`;
  if (owner.reported.has(key)) return;
  owner.reported.add(key);
  const err = { mesh: object, message };
  owner.errors.push(err);
  if (typeof owner.onError === 'function') {
    try {
      owner.onError(err);
    } catch {
      // The user's callback may not break the render loop either.
    }
  }
}
