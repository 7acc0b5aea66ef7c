# A 16 x 16 CMYK JPEG (Adobe APP14, transform 0), flat per component, written by hand.
import struct
def seg(m, data): return b'\xff'+bytes([m])+struct.pack('>H', len(data)+2)+data
vals=[200,50,100,30]
out=b'\xff\xd8'
out+=seg(0xEE, b'Adobe'+struct.pack('>HHHB',100,0,0,0))
out+=seg(0xDB, b'\x00'+bytes([1]*64))
out+=seg(0xC0, struct.pack('>BHHB',8,16,16,4)+b''.join(bytes([i+1,0x11,0]) for i in range(4)))
dc_bits=[0,1,5,1,1,1,1,1,1,0,0,0,0,0,0,0]; dc_vals=list(range(12))
out+=seg(0xC4, bytes([0x00])+bytes(dc_bits)+bytes(dc_vals))
ac_bits=[0,2]+[0]*14; ac_vals=[0,1]
out+=seg(0xC4, bytes([0x10])+bytes(ac_bits)+bytes(ac_vals))
out+=seg(0xDA, bytes([4])+b''.join(bytes([i+1,0x00]) for i in range(4))+bytes([0,63,0]))
# DC codes (standard luminance)
codes={}; code=0; k=0
for l,n in enumerate(dc_bits,1):
    for _ in range(n): codes[dc_vals[k]]=format(code,'0%db'%l); code+=1; k+=1
    code<<=1
bits=''
pred=[0]*4
for blk in range(4):
    for c in range(4):
        dc=8*(vals[c]-128); d=dc-pred[c]; pred[c]=dc
        cat=abs(d).bit_length(); bits+=codes[cat]
        if cat: bits+=format(d if d>0 else d+(1<<cat)-1,'0%db'%cat)
        bits+='00'  # EOB
bits+='1'*((8-len(bits)%8)%8)
data=bytes(int(bits[i:i+8],2) for i in range(0,len(bits),8))
data=data.replace(b'\xff',b'\xff\x00')
out+=data+b'\xff\xd9'
open('cmyk.jpg','wb').write(out)
