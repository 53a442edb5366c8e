// The preview as a light direction pad: drag it, or focus it and press the arrow keys.
import { $, clamp } from './dom.js';
import { LIGHT, LIGHT_FALLBACK, setValue, state, valueOf } from './state.js';

function lightValue(name) {
  const value = valueOf(name);
  return value === null ? LIGHT_FALLBACK[name] : value;
}

function moveLight(azimuth, elevation) {
  const az = state.specs.get(LIGHT.azimuth);
  const el = state.specs.get(LIGHT.elevation);
  if (!az || !el) return;
  // Wrap the azimuth into (−180, 180]; the elevation stops at the poles.
  const wrapped = ((((azimuth + 180) % 360) + 360) % 360) - 180;
  setValue(LIGHT.azimuth, Number(clamp(wrapped, az.min, az.max).toFixed(1)), null);
  setValue(LIGHT.elevation, Number(clamp(elevation, el.min, el.max).toFixed(1)), null);
}

function onKey(event) {
  const step = event.shiftKey ? 15 : 5;
  const moves = { ArrowLeft: [-step, 0], ArrowRight: [step, 0], ArrowUp: [0, step],
    ArrowDown: [0, -step] };
  const move = moves[event.key];
  if (!move) return;
  event.preventDefault();
  moveLight(lightValue(LIGHT.azimuth) + move[0], lightValue(LIGHT.elevation) + move[1]);
}

export function setupLightPad() {
  const stage = $('#stage');
  let drag = null;
  stage.addEventListener('pointerdown', (event) => {
    if (event.button !== 0) return;
    stage.setPointerCapture(event.pointerId);
    stage.classList.add('dragging');
    drag = { x: event.clientX, y: event.clientY, az: lightValue(LIGHT.azimuth),
      el: lightValue(LIGHT.elevation) };
    event.preventDefault();
  });
  stage.addEventListener('pointermove', (event) => {
    if (!drag) return;
    const box = stage.getBoundingClientRect();
    // One width of drag is a full turn; one height, pole to pole.
    moveLight(drag.az + ((event.clientX - drag.x) / box.width) * 360,
      drag.el - ((event.clientY - drag.y) / box.height) * 180);
  });
  const end = () => {
    drag = null;
    stage.classList.remove('dragging');
  };
  stage.addEventListener('pointerup', end);
  stage.addEventListener('pointercancel', end);
  stage.addEventListener('keydown', onKey);
}
