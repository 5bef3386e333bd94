#!/usr/bin/env python3
"""Intervals for `faint reproduce phd` runs: mean OSPA and mean std of count per SNR and
variant of two runs of the same seeds (a preset and a candidate), with 95 % percentile
bootstrap intervals over the runs (2000 resamples, the same resampled runs for both, so
the difference's interval is paired).

Reads the shard files that `--shard 0/1` writes (the per-run counts and OSPA per frame;
the unsharded outputs hold only per-frame means). Written for runs with
`--snr-db 9,7,5 --variants pso-phd-kmeans,pso-phd-dbscan`; the values equal the
`summary.csv` of `faint merge` on the same shard (std of count over runs with ddof 0).

    python3 tools/phd_intervals.py PRESET.faint-shard CANDIDATE.faint-shard

Standard library only (a minimal CBOR reader).
"""
import math
import random
import struct
import sys

def dec(b, i=0):
    ib=b[i]; mt=ib>>5; ai=ib&31; i+=1
    def arg(ai,i):
        if ai<24: return ai,i
        if ai==24: return b[i],i+1
        if ai==25: return struct.unpack('>H',b[i:i+2])[0],i+2
        if ai==26: return struct.unpack('>I',b[i:i+4])[0],i+4
        if ai==27: return struct.unpack('>Q',b[i:i+8])[0],i+8
        if ai==31: return None,i
        raise ValueError(ai)
    if mt==7:
        if ai==20: return False,i
        if ai==21: return True,i
        if ai==22 or ai==23: return None,i
        if ai==25: return struct.unpack('>e',b[i:i+2])[0],i+2
        if ai==26: return struct.unpack('>f',b[i:i+4])[0],i+4
        if ai==27: return struct.unpack('>d',b[i:i+8])[0],i+8
        if ai<24: return ('simple',ai),i
        raise ValueError('mt7 %d'%ai)
    v,i=arg(ai,i)
    if mt==0: return v,i
    if mt==1: return -1-v,i
    if mt==2 or mt==3:
        if v is None:
            out=b'' if mt==2 else ''
            while b[i]!=0xff:
                c,i=dec(b,i); out+=c
            return out,i+1
        s=b[i:i+v]; i+=v
        return (s if mt==2 else s.decode()),i
    if mt==4:
        out=[]
        if v is None:
            while b[i]!=0xff:
                x,i=dec(b,i); out.append(x)
            return out,i+1
        for _ in range(v):
            x,i=dec(b,i); out.append(x)
        return out,i
    if mt==5:
        out={}
        if v is None:
            while b[i]!=0xff:
                k,i=dec(b,i); x,i=dec(b,i); out[k if not isinstance(k,list) else tuple(k)]=x
            return out,i+1
        for _ in range(v):
            k,i=dec(b,i); x,i=dec(b,i); out[k if not isinstance(k,(list,dict)) else str(k)]=x
        return out,i
    if mt==6:
        x,i=dec(b,i); return x,i
def cbor_load(path):
    b=open(path,'rb').read()
    v,i=dec(b,0)
    return v

VAR=['PSO-PHD-TBD (K-means)','PSO-PHD-TBD (DBSCAN)']
SNR=[9,7,5]
def load(path):
    v=cbor_load(path)
    out={}
    for bi,b in enumerate(v['batches']):
        for vi in range(2):
            out[(SNR[bi],vi)]=[(r[vi]['counts'],r[vi]['ospa']) for r in b['results']]
    return out
def mean_ospa(runs):
    return sum(sum(o) for c,o in runs)/(len(runs)*len(runs[0][1]))
def mean_std(runs, ddof):
    F=len(runs[0][0]); R=len(runs); tot=0
    for f in range(F):
        xs=[r[0][f] for r in runs]; m=sum(xs)/R
        tot+=math.sqrt(sum((x-m)**2 for x in xs)/(R-ddof))
    return tot/F
def boot(a,b,B=2000,seed=1):
    rnd=random.Random(seed); R=len(a)
    res={'ospa':[], 'std':[], 'dospa':[], 'dstd':[], 'ospa_b':[], 'std_b':[]}
    for _ in range(B):
        idx=[rnd.randrange(R) for _ in range(R)]
        A=[a[i] for i in idx]; Bb=[b[i] for i in idx]
        oa,ob=mean_ospa(A),mean_ospa(Bb); sa,sb=mean_std(A,DD),mean_std(Bb,DD)
        res['ospa'].append(oa); res['std'].append(sa); res['ospa_b'].append(ob); res['std_b'].append(sb)
        res['dospa'].append(ob-oa); res['dstd'].append(sb-sa)
    q=lambda xs:(sorted(xs)[int(0.025*B)], sorted(xs)[int(0.975*B)-1])
    return {k:q(v) for k,v in res.items()}
DD=0
base=load(sys.argv[1]); cand=load(sys.argv[2])
print(f"preset={sys.argv[1]} candidate={sys.argv[2]} ddof={DD}; 95% percentile bootstrap over runs (2000 resamples, paired)")
print("| SNR | variant | OSPA preset [95%] | OSPA cand [95%] | diff cand-preset [95%] | count std preset [95%] | count std cand [95%] | diff [95%] |")
for s in SNR:
    for vi in range(2):
        a=base[(s,vi)]; b=cand[(s,vi)]
        q=boot(a,b)
        f=lambda x:f"{x:.2f}"
        iv=lambda t:f"[{t[0]:.2f}, {t[1]:.2f}]"
        print(f"| {s} | {VAR[vi]} | {f(mean_ospa(a))} {iv(q['ospa'])} | {f(mean_ospa(b))} {iv(q['ospa_b'])} | {mean_ospa(b)-mean_ospa(a):+.2f} {iv(q['dospa'])} | {f(mean_std(a,DD))} {iv(q['std'])} | {f(mean_std(b,DD))} {iv(q['std_b'])} | {mean_std(b,DD)-mean_std(a,DD):+.3f} [{q['dstd'][0]:+.3f}, {q['dstd'][1]:+.3f}] |")
