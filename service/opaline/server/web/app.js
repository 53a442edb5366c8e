// Opaline's material tuner: controls built from the service's OpenAPI schema,
// a live preview and MDF plot fetched from the API, and the same state copied
// as a JSON body, a curl command, a CLI command or a link to this page.
//
// State is the preset plus the fields the user changed from the preset's
// values (GET /v1/presets/{name}); only those are sent, so the browser and the
// service cache every repeated view.
'use strict';

(() => {
  const API = {
    openapi: '/openapi.json',
    presets: '/v1/presets',
    render: '/v1/render',
    mdf: '/v1/mdf',
  };
  const DEBOUNCE_MS = 150;
  const MDF_PLOT_SIZE = 256;
  const MAX_RETRIES = 5; // of a 503, each after its Retry-After

  // How the page arranges the schema's fields; fields it does not name go to
  // the last group, so a new API field still gets a control.
  const GROUPS = [
    ['material', 'Material', ['mdf', 'ex', 'ey', 'mu_f', 'alpha', 'beta', 'theta1', 'theta2',
      'kd', 'ks', 'albedo', 'f0']],
    ['physical', 'Iridescence source', ['iridescence', 'film_ior', 'film_thickness_min',
      'film_thickness_max', 'substrate_ior', 'grating_pitch', 'grating_orders', 'grating_depth']],
    ['light', 'Light', ['light_azimuth', 'light_elevation']],
    ['output', 'Output', ['width', 'height', 'quality', 'format', 'exposure', 'tonemap',
      'transparent']],
    ['scene', 'Mesh and camera', ['mesh', 'tangent_field', 'tangent_axis', 'camera_azimuth',
      'camera_elevation', 'camera_distance']],
    ['environment', 'Environment', ['environment', 'environment_rotation',
      'environment_intensity', 'environment_lights', 'environment_background']],
    ['tier', 'Quality tier overrides', ['samples', 'wavelengths', 'aa']],
  ];
  const MATERIAL = new Set([...GROUPS[0][2], ...GROUPS[1][2]]);
  // Which MDF reads which parameter (docs/design.md §1); the others are dimmed.
  const MDF_ONLY = { ex: 'ashikhmin', ey: 'ashikhmin', mu_f: 'multipeak', alpha: 'multipeak',
    beta: 'multipeak' };
  // Which iridescence source reads which field (docs/physics.md); the physical
  // sources use the A-S lobe (ex, ey) and none of the paper's rotation fields.
  const SOURCE_ONLY = { film_ior: 'thin-film', film_thickness_min: 'thin-film',
    film_thickness_max: 'thin-film', substrate_ior: 'thin-film', grating_pitch: 'grating',
    grating_orders: 'grating', grating_depth: 'grating' };
  const PAPER_ONLY = ['mdf', 'mu_f', 'alpha', 'beta', 'theta1', 'theta2'];
  // The MDF plot shows D only: these are the material fields it reads.
  const MDF_PLOT_FIELDS = ['mdf', 'ex', 'ey', 'mu_f', 'alpha', 'beta', 'theta1', 'theta2'];
  // Unset = the quality tier's value (which changes with the tier).
  const TIER_FIELDS = new Set(['samples', 'wavelengths', 'aa']);
  const LIGHT = { azimuth: 'light_azimuth', elevation: 'light_elevation' };
  // Where a drag starts while the preset's key light direction is not known.
  const LIGHT_FALLBACK = { light_azimuth: 0, light_elevation: 45 };
  const EXTENSIONS = { png: '.png', png16: '.png', npy: '.npy', webp: '.webp',
    'webp-lossless': '.webp', avif: '.avif', jpeg: '.jpg' };
  const BOOLEANS = new Map([['true', true], ['1', true], ['false', false], ['0', false]]);
  // With access control on, the service wants an API key; the page keeps the one the user
  // types for this tab only (sessionStorage) and sends it as a header, never in a URL.
  const KEY_STORE = 'opaline-api-key';

  const $ = (sel) => document.querySelector(sel);
  const state = {
    specs: new Map(),      // field name → spec read from the schema
    order: [],             // field names in schema order (stable URLs)
    presets: [],
    preset: null,
    info: null,            // GET /v1/presets/{name}
    overrides: {},         // field → value the user changed
    invalid: new Map(),    // field → local message (not a number yet)
    controls: new Map(),   // field → control
    retries: 0,
    presetError: null,     // a preset named in the link that the service does not know
  };

  // ---------------------------------------------------------------- helpers

  function h(tag, attrs = {}, ...children) {
    const node = document.createElement(tag);
    for (const [key, value] of Object.entries(attrs)) {
      if (value === false || value === null || value === undefined) continue;
      if (key === 'text') node.textContent = value;
      else if (key === 'class') node.className = value;
      else node.setAttribute(key, value === true ? '' : String(value));
    }
    for (const child of children) if (child) node.append(child);
    return node;
  }

  function same(a, b) {
    if (Array.isArray(a) || Array.isArray(b)) {
      return Array.isArray(a) && Array.isArray(b) && a.length === b.length &&
        a.every((x, i) => x === b[i]);
    }
    return a === b;
  }

  const clamp = (x, lo, hi) => Math.min(hi, Math.max(lo, x));
  const fmt = (value) => (Array.isArray(value) ? value.map(String).join(',') : String(value));

  function shellQuote(text) {
    return /^[\w@%+=:,./-]+$/.test(text) ? text : `'${text.replace(/'/g, `'\\''`)}'`;
  }

  function authHeaders() {
    const key = sessionStorage.getItem(KEY_STORE);
    return key ? { 'X-API-Key': key } : {};
  }

  // A 403 means access control is on: ask for a key; saving it reloads the page.
  function askForKey() {
    const form = $('#key-form');
    if (!form || !form.hidden) return;
    form.hidden = false;
    form.addEventListener('submit', (event) => {
      event.preventDefault();
      sessionStorage.setItem(KEY_STORE, $('#api-key').value.trim());
      location.reload();
    });
  }

  async function getJSON(url) {
    const resp = await fetch(url, { headers: authHeaders() });
    if (resp.status === 403) askForKey();
    const body = await resp.json().catch(() => null);
    if (!resp.ok) {
      throw Object.assign(new Error(problemLines(body, resp).join('\n')), { status: resp.status });
    }
    return body;
  }

  // An error answer's lines: a 422 gives one per problem, other errors one.
  function problemLines(body, resp) {
    const detail = body && body.detail;
    if (Array.isArray(detail)) return detail.map(String);
    return [detail ? String(detail) : `${resp.status} ${resp.statusText}`];
  }

  // ------------------------------------------------------- schema → specs

  function deref(schema, node) {
    let seen = 0;
    while (node && node.$ref && seen++ < 8) {
      node = node.$ref.split('/').slice(1).reduce((at, key) => (at ? at[key] : undefined), schema);
    }
    return node || {};
  }

  function numberRange(node) {
    const open = (k) => typeof node[k] === 'number';
    return {
      min: node.minimum ?? node.exclusiveMinimum,
      max: node.maximum ?? node.exclusiveMaximum,
      minOpen: open('exclusiveMinimum'),
      maxOpen: open('exclusiveMaximum'),
      integer: node.type === 'integer',
    };
  }

  // One spec per property; optional fields come as anyOf [{…}, {type: null}].
  function specOf(schema, name, prop) {
    const alternatives = (prop.anyOf || prop.oneOf || [prop]).map((alt) => deref(schema, alt));
    const main = alternatives.find((alt) => alt.type !== 'null') || {};
    const spec = { name, description: prop.description || main.description || '' };
    if (main.enum) Object.assign(spec, { kind: 'enum', options: main.enum });
    else if (main.type === 'boolean') spec.kind = 'bool';
    else if (main.type === 'array') {
      spec.kind = 'vector';
      spec.items = (main.prefixItems || []).map((item) => numberRange(deref(schema, item)));
    } else if (main.type === 'number' || main.type === 'integer') {
      Object.assign(spec, { kind: 'number' }, numberRange(main));
    } else spec.kind = 'text';
    return spec;
  }

  function readSchema(openapi) {
    const model = openapi.components.schemas.RenderRequest;
    for (const [name, prop] of Object.entries(model.properties)) {
      if (name === 'preset') continue;
      state.specs.set(name, specOf(openapi, name, prop));
      state.order.push(name);
    }
  }

  // ------------------------------------------------------- slider scales

  // A slider runs 0 … 1000. Fields from 0 up to 100 or more (the exponents
  // reach 1e6) get a log scale, v = c·(10^t − 1), linear near zero; others a
  // linear one. Values are rounded to what a slider step can tell apart.
  const STEPS = 1000;

  function scaleOf(spec) {
    const { min, max } = spec;
    if (!Number.isFinite(min) || !Number.isFinite(max)) return null;
    const round = (v) => (spec.integer ? Math.round(v) : v);
    if (min >= 0 && max >= 100) {
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
    const digits = spec.integer ? 0 : Math.max(0, -Math.floor(Math.log10((max - min) / STEPS)));
    return {
      toValue: (pos) => round(Number((min + ((max - min) * pos) / STEPS).toFixed(digits))),
      toPos: (v) => (STEPS * (clamp(v, min, max) - min)) / (max - min),
    };
  }

  // --------------------------------------------------------------- values

  function defaultOf(name) {
    const info = state.info;
    if (!info) return null;
    if (name in LIGHT_FALLBACK) {
      // The API's `key_light` (where the preset puts its light), when it gives one.
      const key = info.key_light && info.key_light[name.replace('light_', '')];
      return typeof key === 'number' ? key : null;
    }
    if (TIER_FIELDS.has(name)) return info.defaults[name] ?? null;
    if (MATERIAL.has(name)) return info.resolved.material[name] ?? null;
    return info.resolved[name] ?? null;
  }

  const valueOf = (name) => (name in state.overrides ? state.overrides[name] : defaultOf(name));

  // The fields sent: the user's changes, in schema order.
  function changedFields() {
    const fields = {};
    for (const name of state.order) if (name in state.overrides) fields[name] = state.overrides[name];
    return fields;
  }

  function setValue(name, value, source) {
    state.invalid.delete(name);
    if (value === null || value === '' || same(value, defaultOf(name))) delete state.overrides[name];
    else state.overrides[name] = value;
    refreshField(name, source);
    if (name === 'mdf' || name === 'iridescence') refreshInactive();
    schedule();
  }

  function setInvalid(name, message) {
    state.invalid.set(name, message);
    schedule();
  }

  // -------------------------------------------------------------- controls

  function fieldShell(spec, labelFor) {
    const name = spec.name;
    const reset = h('button', {
      type: 'button', class: 'reset', title: `Reset ${name} to the preset's value`,
      'aria-label': `Reset ${name} to the preset's value`, text: '↺',
    });
    reset.addEventListener('click', () => {
      setValue(name, null, null);
      // The button hides itself: keep the keyboard focus in the field.
      const first = state.controls.get(name)?.inputs[0];
      if (first) first.focus();
    });
    const head = h('div', { class: 'field-head' },
      h('label', { for: labelFor, text: name }),
      h('span', { class: 'note', id: `note-${name}` }), reset);
    const wrap = h('div', { class: 'field', 'data-field': name }, head);
    const desc = h('p', { class: 'desc', id: `desc-${name}`, text: spec.description });
    const err = h('p', { class: 'error', id: `err-${name}`, role: 'alert', hidden: true });
    return { wrap, desc, err, reset };
  }

  function numberInput(id, range, label, described) {
    return h('input', {
      type: 'number', id, inputmode: 'decimal', step: 'any', 'aria-label': label,
      min: range.minOpen ? null : range.min, max: range.maxOpen ? null : range.max,
      'aria-describedby': described,
    });
  }

  // A number: slider and number field, kept in step.
  function numberControl(spec) {
    const name = spec.name;
    const shell = fieldShell(spec, `in-${name}`);
    const described = `desc-${name} err-${name}`;
    const input = numberInput(`in-${name}`, spec, null, described);
    if (spec.integer) input.setAttribute('inputmode', 'numeric');
    const scale = scaleOf(spec);
    const row = h('div', { class: 'inputs' });
    let slider = null;
    if (scale) {
      slider = h('input', {
        type: 'range', id: `rng-${name}`, min: 0, max: STEPS, step: 1,
        'aria-label': `${name} slider`, 'aria-describedby': `desc-${name}`,
      });
      slider.addEventListener('input', () => setValue(name, scale.toValue(Number(slider.value)), slider));
      row.append(slider);
    }
    row.append(input);
    input.addEventListener('input', () => {
      if (input.value.trim() === '' && defaultOf(name) === null) {
        setValue(name, null, input);
      } else if (input.validity.badInput || input.value.trim() === '') {
        setInvalid(name, `${name}: enter a number`);
      } else {
        setValue(name, Number(input.value), input);
      }
    });
    shell.wrap.append(row, shell.desc, shell.err);
    return {
      ...shell,
      inputs: [input, slider].filter(Boolean),
      show(value, source) {
        const blank = value === null || value === undefined;
        if (source !== input) input.value = blank ? '' : String(value);
        input.placeholder = blank ? (TIER_FIELDS.has(name) ? 'tier' : 'preset') : '';
        if (slider && source !== slider) {
          const shown = blank ? (LIGHT_FALLBACK[name] ?? spec.min) : value;
          slider.value = String(Math.round(scale.toPos(Number(shown))));
        }
        if (slider) slider.setAttribute('aria-valuetext', blank ? 'preset value' : String(value));
        shell.wrap.classList.toggle('unset', blank);
      },
    };
  }

  function enumControl(spec) {
    const name = spec.name;
    const shell = fieldShell(spec, `in-${name}`);
    const select = h('select', { id: `in-${name}`, 'aria-describedby': `desc-${name} err-${name}` });
    if (TIER_FIELDS.has(name)) select.append(h('option', { value: '', text: "tier's value" }));
    for (const option of spec.options) select.append(h('option', { value: option, text: option }));
    select.addEventListener('change', () => setValue(name, select.value || null, select));
    shell.wrap.append(h('div', { class: 'inputs' }, select), shell.desc, shell.err);
    return { ...shell, inputs: [select], show: (value) => { select.value = value ?? ''; } };
  }

  function boolControl(spec) {
    const name = spec.name;
    const shell = fieldShell(spec, `in-${name}`);
    const box = h('input', { type: 'checkbox', id: `in-${name}`,
      'aria-describedby': `desc-${name} err-${name}` });
    box.addEventListener('change', () => setValue(name, box.checked, box));
    shell.wrap.classList.add('bool');
    shell.wrap.firstChild.prepend(box);
    shell.wrap.append(shell.desc, shell.err);
    return { ...shell, inputs: [box], show: (value) => { box.checked = Boolean(value); } };
  }

  // Linear RGB ↔ the sRGB hex of <input type=color>.
  const toSrgb = (c) => (c <= 0.0031308 ? 12.92 * c : 1.055 * c ** (1 / 2.4) - 0.055);
  const toLinear = (c) => (c <= 0.04045 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4);

  function hexOf(rgb) {
    return '#' + rgb.map((c) => Math.round(clamp(toSrgb(clamp(c, 0, 1)), 0, 1) * 255)
      .toString(16).padStart(2, '0')).join('');
  }

  // A colour (linear RGB triple): three number fields and a colour picker.
  function vectorControl(spec) {
    const name = spec.name;
    const shell = fieldShell(spec, `in-${name}-0`);
    const names = ['red', 'green', 'blue'];
    const inputs = spec.items.map((range, i) =>
      numberInput(`in-${name}-${i}`, range, `${name} ${names[i]}`, `desc-${name} err-${name}`));
    const color = h('input', { type: 'color', id: `in-${name}-color`,
      'aria-label': `${name} colour picker (sRGB)`, 'aria-describedby': `desc-${name}` });
    const row = h('div', { class: 'inputs vector' }, color);
    inputs.forEach((input, i) => {
      row.append(h('label', { class: 'channel', for: input.id, text: 'RGB'[i] }), input);
      input.addEventListener('input', () => {
        if (input.validity.badInput || input.value.trim() === '') {
          setInvalid(name, `${name}: enter three numbers`);
          return;
        }
        const value = inputs.map((x) => Number(x.value));
        if (value.some((x) => !Number.isFinite(x))) setInvalid(name, `${name}: enter three numbers`);
        else setValue(name, value, input);
      });
    });
    color.addEventListener('input', () => {
      const hex = color.value.slice(1);
      const value = [0, 2, 4].map((i) =>
        Number(toLinear(parseInt(hex.slice(i, i + 2), 16) / 255).toFixed(4)));
      setValue(name, value, color);
    });
    shell.wrap.append(row, shell.desc, shell.err);
    return {
      ...shell,
      inputs: [...inputs, color],
      show(value, source) {
        const rgb = value || [0, 0, 0];
        inputs.forEach((input, i) => { if (source !== input) input.value = String(rgb[i]); });
        if (source !== color) color.value = hexOf(rgb);
      },
    };
  }

  function textControl(spec) {
    const name = spec.name;
    const shell = fieldShell(spec, `in-${name}`);
    const input = h('input', { type: 'text', id: `in-${name}`,
      'aria-describedby': `desc-${name} err-${name}` });
    input.addEventListener('input', () => setValue(name, input.value.trim() || null, input));
    shell.wrap.append(h('div', { class: 'inputs' }, input), shell.desc, shell.err);
    return { ...shell, inputs: [input], show(value, source) {
      if (source !== input) input.value = value ?? '';
    } };
  }

  const BUILDERS = { number: numberControl, enum: enumControl, bool: boolControl,
    vector: vectorControl, text: textControl };

  function buildControls() {
    const placed = new Set(GROUPS.flatMap((group) => group[2]));
    const rest = state.order.filter((name) => !placed.has(name));
    const root = $('#groups');
    GROUPS.forEach(([id, title, names], index) => {
      const fields = names.concat(index === GROUPS.length - 1 ? rest : [])
        .filter((name) => state.specs.has(name));
      if (!fields.length) return;
      const set = h('fieldset', { class: `group group-${id}`, id: `group-${id}` },
        h('legend', { text: title }));
      for (const name of fields) {
        const spec = state.specs.get(name);
        const control = BUILDERS[spec.kind](spec);
        state.controls.set(name, control);
        set.append(control.wrap);
      }
      if (id === 'tier') {
        root.append(h('details', { class: 'group-details' }, h('summary', { text: title }), set));
      } else root.append(set);
    });
  }

  function refreshField(name, source) {
    const control = state.controls.get(name);
    if (!control) return;
    control.show(valueOf(name), source);
    const changed = name in state.overrides;
    control.wrap.classList.toggle('changed', changed);
    control.reset.hidden = !changed;
  }

  function refreshInactive() {
    const mdf = valueOf('mdf');
    const source = valueOf('iridescence') ?? 'rotation';
    const mark = (name, unused, by) => {
      const control = state.controls.get(name);
      if (!control) return;
      control.wrap.classList.toggle('inactive', unused);
      control.wrap.querySelector('.note').textContent = unused ? `unused by ${by}` : '';
    };
    for (const [name, owner] of Object.entries(MDF_ONLY)) mark(name, mdf !== owner, mdf);
    for (const [name, owner] of Object.entries(SOURCE_ONLY)) mark(name, source !== owner, source);
    if (source !== 'rotation') {
      for (const name of PAPER_ONLY) mark(name, true, source);
      for (const name of ['ex', 'ey']) mark(name, false, source);
    }
  }

  function refreshAll() {
    for (const name of state.controls.keys()) refreshField(name, null);
    refreshInactive();
  }

  // ------------------------------------------------------------- requests

  function renderQuery(forPreview) {
    const query = new URLSearchParams({ preset: state.preset });
    for (const [name, value] of Object.entries(changedFields())) {
      // A browser cannot show .npy: the preview is the PNG of the same render.
      if (forPreview && name === 'format' && value === 'npy') continue;
      query.set(name, fmt(value));
    }
    return query;
  }

  function mdfQuery() {
    // /v1/mdf knows no presets: it gets every field its plot reads.
    const query = new URLSearchParams();
    for (const name of MDF_PLOT_FIELDS) {
      const value = valueOf(name);
      if (value !== null && state.specs.has(name)) query.set(name, fmt(value));
    }
    if ('wavelengths' in state.overrides) query.set('wavelengths', fmt(state.overrides.wavelengths));
    query.set('size', String(MDF_PLOT_SIZE));
    return query;
  }

  // Fetch an image; swap it in only when it is one, keeping the last good one.
  async function loadImage(img, url, signal) {
    if (img.dataset.url === url) return { ok: true, url, kept: true };
    let resp;
    try {
      resp = await fetch(url, { signal, headers: authHeaders() });
    } catch (err) {
      if (err.name === 'AbortError') return { aborted: true };
      return { ok: false, status: 0, lines: ['Cannot reach the service: ' + err.message] };
    }
    if (!resp.ok) {
      if (resp.status === 403) askForKey();
      const body = await resp.json().catch(() => null);
      return {
        ok: false, status: resp.status, retryAfter: Number(resp.headers.get('Retry-After')) || 1,
        lines: problemLines(body, resp),
      };
    }
    const blob = await resp.blob().catch(() => null);
    if (signal.aborted) return { aborted: true };
    if (!blob) return { ok: false, status: 0, lines: ['The image did not arrive whole'] };
    const old = img.src;
    img.src = URL.createObjectURL(blob);
    await img.decode().catch(() => {});
    img.dataset.url = url;
    if (old.startsWith('blob:')) URL.revokeObjectURL(old);
    return { ok: true, url };
  }

  let timer = null;
  let seq = 0;
  let inflight = null;

  // While a hand drags (the light pad or a slider), the preview shows draft renders as
  // fast as the service returns them: at most one in flight, and when it lands the
  // newest state is asked for next (the states passed over meanwhile are never sent).
  // They are drawn at the preview's displayed size × devicePixelRatio and negotiated
  // (format=auto: WebP in browsers that take it). When the hand stops, the draft in
  // flight is cancelled and the chosen request is rendered as usual.
  const live = { active: false, inflight: null, pending: false, frames: 0 };

  function liveQuery() {
    const query = renderQuery(true);
    const job = state.info.resolved;
    const w = valueOf('width') ?? job.width;
    const hgt = valueOf('height') ?? job.height;
    const shown = $('#preview').getBoundingClientRect().width || w;
    const width = clamp(Math.round(shown * (window.devicePixelRatio || 1)), 16, 2048);
    const height = clamp(Math.round((width * hgt) / w), 16, 2048);
    for (const name of TIER_FIELDS) query.delete(name);
    query.set('quality', 'draft');
    query.set('format', 'auto');
    query.set('width', String(width));
    query.set('height', String(height));
    return query;
  }

  async function liveRender() {
    if (live.inflight) {
      live.pending = true;
      return;
    }
    if (!state.info || state.invalid.size) return;
    live.pending = false;
    live.inflight = new AbortController();
    const result = await loadImage($('#preview'), `${API.render}?${liveQuery()}`,
      live.inflight.signal);
    live.inflight = null;
    if (result.ok && !result.kept) {
      live.frames += 1;
      document.body.dataset.liveFrames = String(live.frames);
    }
    if (live.active && live.pending) liveRender();
  }

  function startLive() {
    if (live.active) return;
    live.active = true;
    clearTimeout(timer);
    if (inflight) inflight.abort();  // the chosen render is asked for again at the end
    document.body.classList.remove('loading');
  }

  function endLive() {
    if (!live.active) return;
    live.active = false;
    live.pending = false;
    if (live.inflight) live.inflight.abort();
    live.inflight = null;
    schedule(0);
  }

  function schedule(delay = DEBOUNCE_MS) {
    document.body.dataset.busy = 'true';
    writeOutputs();
    clearTimeout(timer);
    if (live.active) {
      liveRender();
      return;
    }
    timer = setTimeout(update, delay);
  }

  async function update() {
    const mine = ++seq;
    if (inflight) inflight.abort();
    inflight = new AbortController();
    if (!state.info) return;
    if (state.invalid.size) {
      // The fetch just aborted, if any, no longer ends its own loading state.
      document.body.classList.remove('loading');
      clearErrors();
      for (const [name, message] of state.invalid) showError(name, [message]);
      setStatus('Waiting for a valid value…');
      document.body.dataset.busy = 'false';
      return;
    }
    const started = performance.now();
    document.body.classList.add('loading');
    const renderUrl = `${API.render}?${renderQuery(true)}`;
    const mdfUrl = `${API.mdf}?${mdfQuery()}`;
    const results = await Promise.all([
      loadImage($('#preview'), renderUrl, inflight.signal),
      loadImage($('#mdf'), mdfUrl, inflight.signal),
    ]);
    if (mine !== seq || results.some((r) => r.aborted)) return;
    document.body.classList.remove('loading');
    const failed = results.filter((r) => !r.ok);
    const lines = [...new Set(failed.flatMap((r) => r.lines))];
    clearErrors();
    if (state.presetError) lines.push(state.presetError);
    routeErrors(lines);
    const busy = failed.find((r) => r.status === 503);
    if (busy && state.retries < MAX_RETRIES) {
      state.retries += 1;
      setStatus(`The service is busy; trying again in ${busy.retryAfter} s ` +
        `(${state.retries} of ${MAX_RETRIES})…`);
      timer = setTimeout(update, busy.retryAfter * 1000);
      return;
    }
    state.retries = 0;
    if (!failed.length) {
      const job = state.info.resolved;
      const w = valueOf('width') ?? job.width;
      const hgt = valueOf('height') ?? job.height;
      $('#preview').alt = `Preview of ${state.preset}`;
      const npy = valueOf('format') === 'npy' ? ' · shown as PNG (npy is float data)' : '';
      const took = results.every((r) => r.kept) ? ''
        : ` · ${Math.round(performance.now() - started)} ms`;
      setStatus(`${state.preset} · ${w}×${hgt} · ${valueOf('quality')}${took}${npy}`);
    } else {
      showProblemSummary(lines);
    }
    document.body.dataset.busy = 'false';
  }

  // ---------------------------------------------------------------- errors

  // An API message starts with the field it is about: "mu_f='2000' is out of
  // range …", "albedo.0=…", "width=… on this service"; others go by the preview.
  function fieldOf(line) {
    const match = /^([A-Za-z_][\w]*)/.exec(line);
    const name = match && match[1];
    if (name === 'preset') return 'preset';
    return name && state.controls.has(name) ? name : null;
  }

  function routeErrors(lines) {
    const byField = new Map();
    for (const line of lines) {
      const name = fieldOf(line) || 'general';
      byField.set(name, [...(byField.get(name) || []), line]);
    }
    for (const [name, list] of byField) showError(name, list);
  }

  function showError(name, lines) {
    const err = $(`#err-${name}`);
    if (!err) return;
    err.textContent = lines.join('\n');
    err.hidden = false;
    const control = state.controls.get(name);
    if (control) {
      control.wrap.classList.add('has-error');
      for (const input of control.inputs) input.setAttribute('aria-invalid', 'true');
    }
    if (name === 'preset') $('#preset').setAttribute('aria-invalid', 'true');
  }

  function clearErrors() {
    for (const err of document.querySelectorAll('.error[id^="err-"]')) {
      err.hidden = true;
      err.textContent = '';
    }
    for (const node of document.querySelectorAll('.has-error')) node.classList.remove('has-error');
    for (const node of document.querySelectorAll('[aria-invalid]')) node.removeAttribute('aria-invalid');
  }

  const setStatus = (text) => { $('#status').textContent = text; };

  // "Showing the last good image; see ex, albedo", each name a link to its control.
  function showProblemSummary(lines) {
    const names = [...new Set(lines.map(fieldOf).filter((name) => name && name !== 'preset'))];
    const status = $('#status');
    status.textContent = `Showing the last good image${names.length ? '; see ' : '.'}`;
    names.forEach((name, i) => {
      const input = state.controls.get(name).inputs[0];
      const link = h('a', { href: `#${input.id}`, text: name });
      link.addEventListener('click', (event) => {
        event.preventDefault();
        input.scrollIntoView({ block: 'center' });
        input.focus({ preventScroll: true });
      });
      status.append(i ? ', ' : '', link);
    });
  }

  // ------------------------------------------------------- copy as / link

  function pageUrl() {
    const url = new URL(location.href);
    url.search = renderQuery(false).toString();
    url.hash = '';
    return url.toString();
  }

  function writeOutputs() {
    if (!state.preset) return;
    const fields = changedFields();
    const body = { preset: state.preset, ...fields };
    const file = state.preset + (EXTENSIONS[valueOf('format')] || '.png');
    const endpoint = new URL(API.render, location.href).toString();
    $('#copy-json').value = JSON.stringify(body, null, 2);
    const keyArgs = sessionStorage.getItem(KEY_STORE) ? ['-H', '"X-API-Key: $OPALINE_API_KEY"'] : [];
    $('#copy-curl').value = ['curl', '-fsS', shellQuote(endpoint), ...keyArgs,
      '-H', shellQuote('Content-Type: application/json'),
      '-d', shellQuote(JSON.stringify(body)), '-o', shellQuote(file)].join(' ');
    $('#copy-cli').value = cliCommand(fields, file);
    const link = pageUrl();
    $('#copy-url').value = link;
    if (link !== location.href) history.replaceState(null, '', link);
  }

  function cliCommand(fields, file) {
    const args = ['opaline', 'render', shellQuote(state.preset)];
    const rest = { ...fields };
    if ('width' in rest || 'height' in rest) {
      args.push('--size', `${valueOf('width')}x${valueOf('height')}`);
      delete rest.width;
      delete rest.height;
    }
    for (const option of ['quality', 'format']) {
      if (option in rest) args.push(`--${option}`, shellQuote(fmt(rest[option])));
      delete rest[option];
    }
    if (rest.transparent === true) {
      args.push('--transparent');
      delete rest.transparent;
    }
    for (const [name, value] of Object.entries(rest)) {
      args.push('--set', shellQuote(`${name}=${fmt(value)}`));
    }
    args.push('-o', shellQuote(file));
    return args.join(' ');
  }

  function selectedCopy() {
    return $('input[name="copy-kind"]:checked').value;
  }

  function showCopy() {
    const kind = selectedCopy();
    for (const area of document.querySelectorAll('.copy-text')) {
      area.hidden = area.id !== `copy-${kind}`;
    }
    $('#copy-done').textContent = '';
  }

  async function copySelected() {
    const area = $(`#copy-${selectedCopy()}`);
    try {
      await navigator.clipboard.writeText(area.value);
    } catch {
      area.focus();
      area.select(); // no clipboard API (plain http): select it for Ctrl+C
      if (!document.execCommand || !document.execCommand('copy')) {
        $('#copy-done').textContent = 'Selected: press Ctrl+C';
        return;
      }
    }
    $('#copy-done').textContent = 'Copied';
  }

  // The page's query string is the render's: parse it back into overrides.
  function parseValue(spec, text) {
    if (spec.kind === 'number') {
      const value = Number(text);
      return text.trim() !== '' && Number.isFinite(value) ? value : undefined;
    }
    if (spec.kind === 'vector') {
      const value = text.split(',').map(Number);
      return value.length === spec.items.length && value.every(Number.isFinite) ? value : undefined;
    }
    if (spec.kind === 'bool') return BOOLEANS.get(text);
    if (spec.kind === 'enum') return spec.options.includes(text) ? text : undefined;
    return text;
  }

  function overridesFromUrl(query) {
    const overrides = {};
    for (const [name, text] of query) {
      const spec = state.specs.get(name);
      const value = spec && parseValue(spec, text);
      if (value !== undefined) overrides[name] = value;
    }
    return overrides;
  }

  // --------------------------------------------------------------- presets

  async function choosePreset(name, overrides) {
    document.body.dataset.busy = 'true';
    let info;
    try {
      info = await getJSON(`${API.presets}/${encodeURIComponent(name)}`);
    } catch (err) {
      clearErrors();
      showError(err.status === 404 ? 'preset' : 'general', [err.message]);
      $('#preset').value = state.preset || '';
      document.body.dataset.busy = 'false';
      return false;
    }
    state.preset = name;
    state.info = info;
    state.invalid.clear();
    $('#preset').value = name;
    $('#preset-desc').textContent = `${info.description} ${info.figure ? `(${info.figure})` : ''}`;
    // Material changes belong to the old preset; size, light and output stay.
    const kept = overrides ?? Object.fromEntries(
      Object.entries(state.overrides).filter(([field]) => !MATERIAL.has(field)));
    state.overrides = {};
    for (const [field, value] of Object.entries(kept)) {
      if (!same(value, defaultOf(field))) state.overrides[field] = value;
    }
    refreshAll();
    schedule(0);
    return true;
  }

  // ------------------------------------------------------------ light pad

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

  function setupLightPad() {
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
    stage.addEventListener('keydown', (event) => {
      const step = event.shiftKey ? 15 : 5;
      const moves = { ArrowLeft: [-step, 0], ArrowRight: [step, 0], ArrowUp: [0, step],
        ArrowDown: [0, -step] };
      const move = moves[event.key];
      if (!move) return;
      event.preventDefault();
      moveLight(lightValue(LIGHT.azimuth) + move[0], lightValue(LIGHT.elevation) + move[1]);
    });
  }

  // ------------------------------------------------------------------ start

  async function start() {
    let openapi;
    try {
      [openapi, state.presets] = await Promise.all([getJSON(API.openapi), getJSON(API.presets)]);
    } catch (err) {
      showError('general', [`Cannot load the API description: ${err.message}`]);
      setStatus('');
      document.body.dataset.busy = 'false';
      return;
    }
    readSchema(openapi);
    buildControls();
    const picker = $('#preset');
    for (const preset of state.presets) {
      picker.append(h('option', { value: preset.name, text: preset.name }));
    }
    const fallback = openapi.components.schemas.RenderRequest.properties.preset?.default;
    const names = state.presets.map((p) => p.name);
    const query = new URLSearchParams(location.search);
    const wanted = query.get('preset') || (names.includes(fallback) ? fallback : names[0]);

    picker.addEventListener('change', () => {
      state.presetError = null;
      choosePreset(picker.value, null);
    });
    $('#reset-all').addEventListener('click', () => {
      state.overrides = {};
      state.invalid.clear();
      refreshAll();
      schedule(0);
    });
    for (const radio of document.querySelectorAll('input[name="copy-kind"]')) {
      radio.addEventListener('change', showCopy);
    }
    $('#copy-button').addEventListener('click', copySelected);
    $('#controls').addEventListener('submit', (event) => event.preventDefault());
    setupLightPad();
    // A drag is live from the press on the light pad or a slider to the release.
    document.addEventListener('pointerdown', (event) => {
      if (event.button === 0 && event.target.closest('#stage, input[type="range"]')) startLive();
    }, true);
    for (const kind of ['pointerup', 'pointercancel']) document.addEventListener(kind, endLive, true);

    if (!(await choosePreset(wanted, overridesFromUrl(query))) && wanted !== names[0]) {
      state.presetError = $('#err-preset').textContent;
      await choosePreset(names.includes(fallback) ? fallback : names[0], {});
    }
  }

  // For assets.js (mesh upload, downloads, turntables): the few things it needs.
  window.opaline = { setValue, changedFields, renderQuery, valueOf,
    preset: () => state.preset, problemLines };
  start();
})();
