// SPDX-License-Identifier: GPL-2.0-or-later
// A reader for the part of YAML that rfbsim's scenario and map files use: block mappings and sequences by
// indentation, `- key: value` items, one-line flow sequences and mappings ([1, 2], {count: 5, step: [3.5, 0]}),
// numbers, booleans, null and plain or quoted strings, # comments. The browser tests need no YAML package for
// it (web/node_modules holds only the page's tools). Anything else (anchors, multi-line strings, tabs) is an
// error that names the file and line, never a silent misreading.

// The text of a line without its comment: a # at the start or after a space, outside quotes.
function stripComment(line) {
  let quote = null;
  for (let i = 0; i < line.length; i += 1) {
    const c = line[i];
    if (quote) {
      if (c === quote) {
        quote = null;
      }
    } else if (c === '"' || c === "'") {
      quote = c;
    } else if (c === '#' && (i === 0 || /\s/.test(line[i - 1]))) {
      return line.slice(0, i);
    }
  }
  return line;
}

// A plain scalar: number, boolean, null, else the string itself.
function plainScalar(text) {
  if (/^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$/.test(text)) {
    return Number(text);
  }
  if (text === 'true' || text === 'false') {
    return text === 'true';
  }
  if (text === 'null' || text === '~' || text === '') {
    return null;
  }
  return text;
}

// Parses one flow value ([...], {...}, a quoted or plain scalar) that fills `text`; fail(message) throws.
function parseFlow(text, fail) {
  let i = 0;
  const skip = () => {
    while (i < text.length && text[i] === ' ') {
      i += 1;
    }
  };
  const value = () => {
    skip();
    const c = text[i];
    if (c === '[' || c === '{') {
      const close = c === '[' ? ']' : '}';
      const out = c === '[' ? [] : {};
      i += 1;
      skip();
      if (text[i] === close) {
        i += 1;
        return out;
      }
      for (;;) {
        if (c === '[') {
          out.push(value());
        } else {
          const key = scalar(':');
          skip();
          if (text[i] !== ':') {
            fail(`expected ':' after '${key}' in '${text}'`);
          }
          i += 1;
          out[key] = value();
        }
        skip();
        if (text[i] === close) {
          i += 1;
          return out;
        }
        if (text[i] !== ',') {
          fail(`expected ',' or '${close}' at column ${i + 1} of '${text}'`);
        }
        i += 1;
      }
    }
    return scalar(',]}');
  };
  // A quoted string, or a plain scalar up to one of `stops` (and, inside a mapping, ':').
  const scalar = (stops) => {
    skip();
    const c = text[i];
    if (c === '"' || c === "'") {
      const end = text.indexOf(c, i + 1);
      if (end < 0) {
        fail(`unterminated string in '${text}'`);
      }
      const s = text.slice(i + 1, end);
      i = end + 1;
      return s;
    }
    const start = i;
    while (i < text.length && !stops.includes(text[i])) {
      i += 1;
    }
    return plainScalar(text.slice(start, i).trim());
  };
  const result = value();
  skip();
  if (i !== text.length) {
    fail(`unexpected '${text.slice(i)}' after the value in '${text}'`);
  }
  return result;
}

// How many [ and { are open at the end of text (quotes skipped).
function bracketDepth(text) {
  let depth = 0;
  let quote = null;
  for (const c of text) {
    if (quote) {
      quote = c === quote ? null : quote;
    } else if (c === '"' || c === "'") {
      quote = c;
    } else if (c === '[' || c === '{') {
      depth += 1;
    } else if (c === ']' || c === '}') {
      depth -= 1;
    }
  }
  return depth;
}

const KEY = /^([A-Za-z0-9_.-]+)\s*:(?:\s+(.*))?$/;   // key: [value]
const isItem = (text) => text === '-' || text.startsWith('- ');

/// Parses `text` (the contents of `file`, named in errors) and returns plain objects, arrays and scalars.
export function parseYamlSubset(text, file) {
  const lines = [];
  text.split('\n').forEach((raw, index) => {
    const body = stripComment(raw.replace(/\r$/, '')).trimEnd();
    if (body.trim() === '' || body.trim() === '---') {
      return;
    }
    const indent = body.search(/\S/);
    if (body.slice(0, indent).includes('\t')) {
      throw new Error(`${file}:${index + 1}: tab in indentation`);
    }
    lines.push({ indent, text: body.slice(indent), line: index + 1 });
  });
  let pos = 0;
  const failAt = (line) => (message) => {
    throw new Error(`${file}:${line}: ${message}`);
  };
  const valueOf = (text, line) => {
    if (/^[|>&*!]/.test(text)) {
      failAt(line)(`'${text}': block scalars, anchors, aliases and tags are not supported`);
    }
    // Only flow collections and quoted strings are parsed as flow: a plain block scalar may hold commas.
    if (!/^[[{"']/.test(text)) {
      return plainScalar(text);
    }
    // A flow collection may go on over the next lines (more indented) until its brackets close.
    let joined = text;
    while (bracketDepth(joined) > 0 && pos < lines.length) {
      joined += ` ${lines[pos].text}`;
      pos += 1;
    }
    return parseFlow(joined, failAt(line));
  };

  function block() {
    return isItem(lines[pos].text) ? sequence(lines[pos].indent) : mapping(lines[pos].indent);
  }

  function mapping(indent) {
    const out = {};
    while (pos < lines.length && lines[pos].indent === indent && !isItem(lines[pos].text)) {
      const { text, line } = lines[pos];
      const match = KEY.exec(text);
      if (!match) {
        failAt(line)(`expected 'key: value', found '${text}'`);
      }
      pos += 1;
      const [, key, rest] = match;
      if (rest !== undefined && rest.trim() !== '') {
        out[key] = valueOf(rest.trim(), line);
      } else if (pos < lines.length && lines[pos].indent > indent) {
        out[key] = block();
      } else if (pos < lines.length && lines[pos].indent === indent && isItem(lines[pos].text)) {
        out[key] = sequence(indent);   // "key:" followed by "- item" at the key's own indentation
      } else {
        out[key] = null;
      }
    }
    if (pos < lines.length && lines[pos].indent > indent) {
      failAt(lines[pos].line)('unexpected indentation');
    }
    return out;
  }

  function sequence(indent) {
    const out = [];
    while (pos < lines.length && lines[pos].indent === indent && isItem(lines[pos].text)) {
      const { text, line } = lines[pos];
      const rest = text.slice(1).trim();
      if (rest === '') {
        pos += 1;
        if (pos >= lines.length || lines[pos].indent <= indent) {
          out.push(null);
        } else {
          out.push(block());
        }
      } else if (KEY.test(rest)) {
        // "- key: value" opens a mapping whose keys line up with this first key.
        lines[pos] = { indent: indent + text.indexOf(rest), text: rest, line };
        out.push(mapping(lines[pos].indent));
      } else {
        pos += 1;   // before valueOf, which may take continuation lines from here
        out.push(valueOf(rest, line));
      }
    }
    return out;
  }

  if (lines.length === 0) {
    return null;
  }
  const document = block();
  if (pos < lines.length) {
    failAt(lines[pos].line)(`unexpected '${lines[pos].text}' (indentation does not match)`);
  }
  return document;
}
