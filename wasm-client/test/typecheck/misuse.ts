// Wrong uses of the API that `tsc --noEmit` must reject (test/package_test.mjs checks each line number
// is reported): a check that cannot fail proves nothing.
import { connect, type WireConnection, type PropertyMember, type RRError } from "robotraconteur-wasm";

async function wrong(w: WireConnection<number>, p: PropertyMember<number>, e: RRError): Promise<void> {
  await connect(42);                      // MISUSE: url is a string
  w.inValue = 3;                          // MISUSE: inValue is readonly
  const s: string = await p.get();        // MISUSE: a number property
  const c: string = e.code;               // MISUSE: code is a number
  await connect("rr+ws://h/?service=x", { timeout: 5 });  // MISUSE: the option is timeoutMs
}
export { wrong };
