// How a sweep's bench is named on the page (several benches may share one store,
// docs/database.md): "bench-2 (lab-pc-7)", or the name alone when the host says the same; ''
// for a sweep whose daemon did not record its bench.
export function benchLabel(s) {
  const b = s?.bench;
  if (!b || !b.name) return '';
  return b.host && b.host !== b.name ? `${b.name} (${b.host})` : b.name;
}

// " on bench-2" when the store holds sweeps of more than one bench, else '' (one bench needs no
// naming).
export function onBench(s, all) {
  const names = new Set((all || []).map((x) => x.bench?.name).filter(Boolean));
  const l = benchLabel(s);
  return names.size > 1 && l ? ` on ${l}` : '';
}
