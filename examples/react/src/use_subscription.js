// React hooks over robotraconteur-wasm's reconnecting subscriptions (wasm-client/README.md
// "Subscriptions"): the subscription lives as long as the component, and a wire's newest value is
// component state. A dropped connection is reconnected by the package; the hooks only show it.
import { useEffect, useState } from "react";
import { subscribe } from "robotraconteur-wasm";

/**
 * A ServiceSubscription to `url` while the component is mounted (null before the first effect).
 * `onConnect(client, proxy)` runs on every (re)connection: the place for per-connection requests a
 * device needs before it sends anything (the demo robot's StartStreaming).
 */
export function useServiceSubscription(url, { onConnect, ...options } = {}) {
  const [sub, setSub] = useState(null);
  useEffect(() => {
    const s = subscribe(url, options);
    if (onConnect) s.onConnect(onConnect);
    setSub(s);
    return () => {
      s.close();
    };
    // onConnect and options: read once per url (pass constants)
    // eslint-disable-next-line react-hooks/exhaustive-deps
  }, [url]);
  return sub;
}

/**
 * The wire `name` of the subscription's services: {value, time, count, connected, connects} where value
 * is the newest InValue (undefined until one came), count how many came, connected whether a service is
 * connected now, and
 * connects how many connections were made (1, then 2 after the first reconnect, ...).
 */
export function useWire(sub, name) {
  const [state, setState] = useState({ value: undefined, time: null, count: 0, connected: false, connects: 0 });
  useEffect(() => {
    if (!sub) return undefined;
    const wire = sub.subscribeWire(name);
    const count = () => sub.clients.reduce((n, c) => n + c.connectCount, 0);
    setState((s) => ({ ...s, connected: sub.state === "connected", connects: count() }));
    const offs = [
      wire.onValueChanged((value, time) => setState((s) => ({ ...s, value, time, count: s.count + 1 }))),
      sub.onConnect(() => setState((s) => ({ ...s, connected: true, connects: count() }))),
      sub.onDisconnect(() => setState((s) => ({ ...s, connected: sub.state === "connected" }))),
    ];
    return () => {
      for (const off of offs) off();
      wire.close();
    };
  }, [sub, name]);
  return state;
}
