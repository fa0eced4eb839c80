// What the gateway serves of its optional parts (GET api/features, docs/json-api.md): node discovery
// (the "Discovered" section, api/discovered) and logins (who is logged in, api/whoami). The page asks
// once at start instead of probing those routes, which answer 404 when their feature is off.

/** Features with every optional part off: what a gateway without api/features serves. */
export const NO_FEATURES = Object.freeze({ discovery: false, auth: false });

/** The features of a GET api/features answer; anything but `true` counts as off. */
export function parseFeatures(data) {
  return { discovery: data?.discovery === true, auth: data?.auth === true };
}

/**
 * Asks the gateway once. A gateway that answers with an error status (an old one without the route)
 * serves none of the optional parts; a network failure (the gateway is down) is retried every
 * `retryMs` until it answers. `fetchFn` and `sleep` are replaceable for tests.
 */
export async function loadFeatures({ fetchFn = fetch, retryMs = 2000, sleep = (ms) => new Promise((r) => setTimeout(r, ms)) } = {}) {
  for (;;) {
    let r;
    try {
      r = await fetchFn("api/features", { headers: { Accept: "application/json" }, cache: "no-store" });
    } catch {
      await sleep(retryMs);
      continue;
    }
    if (!r.ok) return NO_FEATURES;
    try {
      return parseFeatures(await r.json());
    } catch {
      return NO_FEATURES;
    }
  }
}
