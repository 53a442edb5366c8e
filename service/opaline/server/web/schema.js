// The service's OpenAPI schema read into one spec per RenderRequest field: its kind,
// range and description, and the page's layout the schema gives (x-groups: the groups
// in page order; per field x-group, x-applies: the values of other fields under which
// it is read, x-tier: its default comes from the quality tier).

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

function kindOf(schema, main) {
  if (main.enum) return { kind: 'enum', options: main.enum };
  if (main.type === 'boolean') return { kind: 'bool' };
  if (main.type === 'array') {
    return { kind: 'vector', items: (main.prefixItems || []).map((i) => numberRange(deref(schema, i))) };
  }
  if (main.type === 'number' || main.type === 'integer') return { kind: 'number', ...numberRange(main) };
  return { kind: 'text' };
}

// One spec per property; optional fields come as anyOf [{…}, {type: null}].
function specOf(schema, name, prop) {
  const alternatives = (prop.anyOf || prop.oneOf || [prop]).map((alt) => deref(schema, alt));
  const main = alternatives.find((alt) => alt.type !== 'null') || {};
  const spec = {
    name,
    description: prop.description || main.description || '',
    default: prop.default ?? null,
    group: prop['x-group'] ?? null,
    applies: prop['x-applies'] ?? null,
    tier: prop['x-tier'] === true,
    ...kindOf(schema, main),
  };
  // A text field with its usual values listed (examples) is picked from them.
  const examples = prop.examples ?? main.examples;
  return spec.kind === 'text' && Array.isArray(examples) ? { ...spec, kind: 'pick', examples } : spec;
}

// { specs: Map name → spec, order: names in schema order, groups: [{id, title, fields}] };
// a field of no known group goes to the last one, so a new API field still gets a control.
export function readSchema(openapi) {
  const model = openapi.components.schemas.RenderRequest;
  const specs = new Map();
  for (const [name, prop] of Object.entries(model.properties)) {
    if (name !== 'preset') specs.set(name, specOf(openapi, name, prop));
  }
  const groups = (model['x-groups'] || []).map(({ id, title }) => ({ id, title, fields: [] }));
  const byId = new Map(groups.map((group) => [group.id, group]));
  for (const spec of specs.values()) {
    const group = byId.get(spec.group) || groups[groups.length - 1];
    if (group) group.fields.push(spec.name);
  }
  return { specs, order: [...specs.keys()], groups, presetDefault: model.properties.preset?.default };
}
