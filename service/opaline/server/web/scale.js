// Slider scales. A slider runs 0 … STEPS. Fields from 0 up to 100 or more (the
// exponents reach 1e6) get a log scale, v = c·(10^t − 1), linear near zero; others a
// linear one. Values are rounded to what a slider step can tell apart.
import { clamp } from './dom.js';

export const STEPS = 1000;

function logScale(spec, round) {
  const { min, max } = spec;
  const c = max / 1e5;
  const top = Math.log10(max / c + 1);
  const snap = (v) => round(v === 0 ? 0 : Number(v.toPrecision(3)));
  return {
    toValue(pos) {
      let v = snap(c * (10 ** ((pos / STEPS) * top) - 1));
      if (spec.minOpen && v <= min) v = snap(c * (10 ** (top / STEPS) - 1));
      return clamp(v, min, max);
    },
    toPos: (v) => (STEPS * Math.log10(clamp(v, min, max) / c + 1)) / top,
  };
}

export function scaleOf(spec) {
  const { min, max } = spec;
  if (!Number.isFinite(min) || !Number.isFinite(max)) return null;
  const round = (v) => (spec.integer ? Math.round(v) : v);
  if (min >= 0 && max >= 100) return logScale(spec, round);
  const digits = spec.integer ? 0 : Math.max(0, -Math.floor(Math.log10((max - min) / STEPS)));
  return {
    toValue: (pos) => round(Number((min + ((max - min) * pos) / STEPS).toFixed(digits))),
    toPos: (v) => (STEPS * (clamp(v, min, max) - min)) / (max - min),
  };
}
