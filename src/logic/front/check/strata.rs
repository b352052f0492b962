//! Stratification: relations grouped into strata in dependency order, with
//! negation and aggregation refused inside a recursive cycle.

use super::super::ast::*;
use super::checker::Checker;
use super::program::Stratum;
use super::walk::collect_deps;
use std::collections::{BTreeMap, BTreeSet};

impl Checker<'_> {
    pub(super) fn stratify(
        &mut self,
        rels: &[RelDecl],
        idx: &BTreeMap<String, usize>,
        rules: &[Rule],
    ) -> Vec<Stratum> {
        let n = rels.len();
        // deps[h] = (body relation, negative or aggregated, span of the use)
        let mut deps: Vec<Vec<(usize, bool, Span)>> = vec![Vec::new(); n];
        for r in rules {
            let h = idx[&r.head.rel];
            collect_deps(&r.body, false, idx, &mut deps[h]);
        }
        let sccs = tarjan(n, &deps);
        let mut scc_of = vec![0usize; n];
        for (k, c) in sccs.iter().enumerate() {
            for &v in c {
                scc_of[v] = k;
            }
        }
        for h in 0..n {
            for &(b, neg, span) in &deps[h] {
                if neg && scc_of[h] == scc_of[b] {
                    let cycle = cycle_path(&deps, b, h, &scc_of);
                    let mut names: Vec<&str> = vec![rels[h].name.as_str()];
                    names.extend(cycle.iter().map(|&i| rels[i].name.as_str()));
                    self.error(span, format!("negation or aggregation of `{}` inside a recursive cycle: {}", rels[b].name, names.join(" -> ")), "the program is not stratifiable; break the cycle so the negated/aggregated relation does not depend on the rule's head");
                }
            }
        }
        sccs.iter()
            .map(|c| {
                let mut relations = c.clone();
                relations.sort();
                let recursive = c.len() > 1 || deps[c[0]].iter().any(|(b, _, _)| *b == c[0]);
                let rules = rules
                    .iter()
                    .enumerate()
                    .filter(|(_, r)| c.contains(&idx[&r.head.rel]))
                    .map(|(i, _)| i)
                    .collect();
                Stratum {
                    relations,
                    rules,
                    recursive,
                }
            })
            .collect()
    }
}

/// Strongly connected components, dependencies first.
fn tarjan(n: usize, deps: &[Vec<(usize, bool, Span)>]) -> Vec<Vec<usize>> {
    struct St<'a> {
        deps: &'a [Vec<(usize, bool, Span)>],
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        on: Vec<bool>,
        stack: Vec<usize>,
        next: usize,
        out: Vec<Vec<usize>>,
    }
    fn visit(s: &mut St, v: usize) {
        // Iterative DFS with an explicit stack of (node, next edge).
        let mut work = vec![(v, 0usize)];
        s.index[v] = Some(s.next);
        s.low[v] = s.next;
        s.next += 1;
        s.stack.push(v);
        s.on[v] = true;
        while let Some(&mut (u, ref mut ei)) = work.last_mut() {
            if *ei < s.deps[u].len() {
                let w = s.deps[u][*ei].0;
                *ei += 1;
                match s.index[w] {
                    None => {
                        s.index[w] = Some(s.next);
                        s.low[w] = s.next;
                        s.next += 1;
                        s.stack.push(w);
                        s.on[w] = true;
                        work.push((w, 0));
                    }
                    Some(iw) if s.on[w] => s.low[u] = s.low[u].min(iw),
                    _ => {}
                }
            } else {
                work.pop();
                if let Some(&(p, _)) = work.last() {
                    s.low[p] = s.low[p].min(s.low[u]);
                }
                if Some(s.low[u]) == s.index[u] {
                    let mut comp = Vec::new();
                    loop {
                        let w = s.stack.pop().unwrap();
                        s.on[w] = false;
                        comp.push(w);
                        if w == u {
                            break;
                        }
                    }
                    s.out.push(comp);
                }
            }
        }
    }
    let mut s = St {
        deps,
        index: vec![None; n],
        low: vec![0; n],
        on: vec![false; n],
        stack: Vec::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in 0..n {
        if s.index[v].is_none() {
            visit(&mut s, v);
        }
    }
    s.out
}

/// A dependency path from `from` to `to` inside one component (inclusive of both ends).
fn cycle_path(
    deps: &[Vec<(usize, bool, Span)>],
    from: usize,
    to: usize,
    scc: &[usize],
) -> Vec<usize> {
    let mut prev: BTreeMap<usize, usize> = BTreeMap::new();
    let mut queue = std::collections::VecDeque::from([from]);
    let mut seen = BTreeSet::from([from]);
    while let Some(u) = queue.pop_front() {
        if u == to {
            break;
        }
        for &(w, _, _) in &deps[u] {
            if scc[w] == scc[from] && seen.insert(w) {
                prev.insert(w, u);
                queue.push_back(w);
            }
        }
    }
    let mut path = vec![to];
    let mut cur = to;
    while cur != from {
        match prev.get(&cur) {
            Some(&p) => {
                path.push(p);
                cur = p;
            }
            None => break,
        }
    }
    path.reverse();
    if from == to {
        path.push(to);
    }
    path
}
