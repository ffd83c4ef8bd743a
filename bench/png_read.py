"""Minimal PNG decoder (8-bit, non-interlaced) for the bench scripts: no PIL on the machines."""
import zlib, struct, numpy as np
def read(path):
    d=open(path,'rb').read(); pos=8; idat=b''; 
    while pos<len(d):
        n,=struct.unpack('>I',d[pos:pos+4]); t=d[pos+4:pos+8]; c=d[pos+8:pos+8+n]; pos+=12+n
        if t==b'IHDR': w,h,bd,ct=struct.unpack('>IIBB',c[:10])
        if t==b'IDAT': idat+=c
    ch={2:3,6:4,0:1,4:2}[ct]; raw=zlib.decompress(idat); stride=w*ch
    out=np.zeros((h,stride),np.uint8); prev=np.zeros(stride,np.int32); i=0
    for y in range(h):
        f=raw[i]; line=np.frombuffer(raw[i+1:i+1+stride],np.uint8).astype(np.int32); i+=1+stride
        cur=np.zeros(stride,np.int32)
        for x in range(stride):
            a=cur[x-ch] if x>=ch else 0; b=prev[x]; cc=prev[x-ch] if x>=ch else 0
            if f==0: v=line[x]
            elif f==1: v=line[x]+a
            elif f==2: v=line[x]+b
            elif f==3: v=line[x]+(a+b)//2
            else:
                p=a+b-cc; pa,pb,pc=abs(p-a),abs(p-b),abs(p-cc)
                v=line[x]+(a if pa<=pb and pa<=pc else (b if pb<=pc else cc))
            cur[x]=v&255
        out[y]=cur; prev=cur
    return out.reshape(h,w,ch)
